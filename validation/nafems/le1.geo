// NAFEMS LE1 "Elliptic membrane" (TNSB Rev. 3, 1990): linear elastic, plane stress.
// A quarter of an elliptic membrane with an elliptic hole, symmetry on x = 0 and y = 0,
// thickness 0.1 m, a uniform outward pressure of 10 MPa on the outer edge BC.
// SI units (m).  NAFEMS points:
//
//   y
//   | B (0, 2.75)
//   |   .   outer ellipse (x/3.25)^2 + (y/2.75)^2 = 1      BC : 10 MPa outward
//   | A (0, 1) .
//   |     .      .  inner ellipse (x/2)^2 + y^2 = 1        AB : u_x = 0
//   |       .     .                                         CD : u_y = 0
//   +--------D----C --> x     D (2, 0), C (3.25, 0)
//
// E = 210 GPa, nu = 0.3.  Target: sigma_yy at D = 92.7 MPa.

SetFactory("OpenCASCADE");

If (!Exists(h))  h  = 0.2;     EndIf   // element size away from D
If (!Exists(hD)) hD = h / 8;   EndIf   // element size at D

Disk(1) = {0, 0, 0, 3.25, 2.75};     // outer ellipse (semi-axes along x, y)
Disk(2) = {0, 0, 0, 2.0, 1.0};       // inner ellipse
Rectangle(3) = {0, 0, 0, 4, 4};      // the first quadrant
BooleanIntersection(4) = { Surface{1}; Delete; }{ Surface{3}; Delete; };
BooleanDifference(5) = { Surface{4}; Delete; }{ Surface{2}; Delete; };

e = 1e-6;
cx0[] = Curve In BoundingBox {-e, -e, -e, e, 3, e};             // AB on x = 0
cy0[] = Curve In BoundingBox {-e, -e, -e, 4, e, e};             // CD on y = 0
cin[] = Curve In BoundingBox {-e, -e, -e, 2 + e, 1 + e, e};     // the hole, A-D (and AB, CD ends)
call[] = Abs(Boundary{ Surface{5}; });
cout[] = call[];
cout[] -= {cx0[], cy0[], cin[]};                                 // BC, the outer ellipse
pD[] = Point In BoundingBox {2 - e, -e, -e, 2 + e, e, e};

Field[1] = Distance;
Field[1].PointsList = {pD[0]};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = hD;
Field[2].SizeMax = h;
Field[2].DistMin = 2 * hD;
Field[2].DistMax = 1.0;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

Physical Surface("membrane") = {5};
Physical Curve("x0_symmetry") = {cx0[]};   // u_x = 0
Physical Curve("y0_symmetry") = {cy0[]};   // u_y = 0
Physical Curve("outer_BC") = {cout[]};     // 10 MPa outward
Physical Point("target") = {pD[0]};        // D
