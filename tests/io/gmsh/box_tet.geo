// Unit box, unstructured tetrahedra. No physical groups, so Gmsh saves every element (points,
// lines, triangles, tetrahedra); the counts are whatever Gmsh makes and are compared with its log.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Mesh.MeshSizeMax = 0.35;
