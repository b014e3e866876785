// A block (solid, tag 1) with a fin (shell, tag 2) hanging from its bottom face and a mast
// (rod, tag 3) hanging from the fin: three dimensions in one conforming mesh, the block's top
// face a boundary label (tag 4).
// Meshed by: gmsh -3 fin.geo -format msh41 -o fin.msh
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.4, 0.2, 0.1};
Point(100) = {0.1, 0.1, 0};
Point(101) = {0.3, 0.1, 0};
Point(102) = {0.3, 0.1, -0.15};
Point(103) = {0.1, 0.1, -0.15};
Point(104) = {0.2, 0.1, -0.15};
Point(105) = {0.2, 0.1, -0.35};
Line(100) = {100, 101};
Line(101) = {101, 102};
Line(102) = {102, 104};
Line(103) = {104, 103};
Line(104) = {103, 100};
Curve Loop(100) = {100, 101, 102, 103, 104};
Plane Surface(100) = {100};
Line(105) = {104, 105};
BooleanFragments{ Volume{1}; Delete; }{ Surface{100}; Curve{105}; Delete; }
Physical Volume("block", 1) = {1};
Physical Surface("fin", 2) = {100};
Physical Curve("mast", 3) = {105};
Physical Surface("top", 4) = Surface In BoundingBox{-0.01, -0.01, 0.09, 0.41, 0.21, 0.11};
Mesh.MeshSizeMax = 0.05;
