// Transfinite square 3 x 3 cut into triangles: 18 triangles on 16 nodes.
SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 1, 1};
Transfinite Curve{:} = 4;
Transfinite Surface{1};
Physical Surface("sheet", 3) = {1};
