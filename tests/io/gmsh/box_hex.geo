// Transfinite box 3 x 3 x 3, recombined: 27 hexahedra on 4 x 4 x 4 = 64 nodes.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 3, 2, 1};
Transfinite Curve{:} = 4;
Transfinite Surface{:};
Recombine Surface{:};
Transfinite Volume{:};
Physical Volume("solid", 5) = {1};
