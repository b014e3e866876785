// Transfinite square 3 x 3, recombined: 9 quadrangles on 16 nodes.
SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 1, 1};
Transfinite Curve{:} = 4;
Transfinite Surface{1};
Recombine Surface{1};
Physical Surface("sheet", 3) = {1};
