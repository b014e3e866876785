// A helical spring of 5 turns (radius 4 cm, pitch 2.5 cm) as 100 straight segments, one Gmsh
// line each (20 per turn), the physical group "spring" (tag 1): a rod whose natural curvature
// and twist come from this rest shape (scenes/rod_spring.json).
// Meshed by: gmsh -1 helix_spring.geo -format msh41 -o helix_spring.msh
n = 100;
turns = 5;
R = 0.04;
pitch = 0.025;
For i In {0:n}
  t = 2 * Pi * turns * i / n;
  Point(i + 1) = {R * Cos(t), R * Sin(t), -pitch * turns * i / n};
EndFor
For i In {1:n}
  Line(i) = {i, i + 1};
EndFor
Transfinite Curve{1:n} = 2;
Physical Curve("spring", 1) = {1:n};
