// The triangulated 3 x 3 square (18 triangles, 16 nodes) extruded in 2 layers: 36 prisms on
// 16 x 3 = 48 nodes.
SetFactory("Built-in");
Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 1, 0}; Point(4) = {0, 1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 2, 3, 4} = 4;
Transfinite Surface{1};
out[] = Extrude {0, 0, 0.5} { Surface{1}; Layers{2}; Recombine; };  // Recombine: prisms, not tetrahedra
Physical Volume("slab", 9) = {out[1]};
