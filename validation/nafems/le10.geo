// NAFEMS LE10 "Thick plate pressure" (TNSB Rev. 3, 1990): linear elastic, 3-D.
// A quarter of a thick elliptic plate with an elliptic hole (the plan of LE1), 0.6 m thick
// (z from -0.3 to 0.3), a uniform pressure of 1 MPa on the upper face z = 0.3.
// SI units (m).  NAFEMS points (primed: the lower face):
//
//   face DCD'C' (y = 0)          : u_y = 0
//   face ABA'B' (x = 0)          : u_x = 0
//   face BCB'C' (outer ellipse)  : u_x = u_y = 0
//   line EE' (outer face, z = 0) : u_z = 0
//
// with A (0, 1), B (0, 2.75), C (3.25, 0), D (2, 0) in plan. E = 210 GPa, nu = 0.3.
// Target: sigma_yy at D = (2, 0, 0.3) = -5.38 MPa.  The plate is made of two layers
// (z < 0 and z > 0) so that the line EE' is a curve of the mesh.

SetFactory("OpenCASCADE");

If (!Exists(h))  h  = 0.3;    EndIf   // element size away from D
If (!Exists(hD)) hD = h / 10; EndIf   // element size at D

t = 0.6;
Disk(1) = {0, 0, -t / 2, 3.25, 2.75};
Disk(2) = {0, 0, -t / 2, 2.0, 1.0};
Rectangle(3) = {0, 0, -t / 2, 4, 4};
BooleanIntersection(4) = { Surface{1}; Delete; }{ Surface{3}; Delete; };
BooleanDifference(5) = { Surface{4}; Delete; }{ Surface{2}; Delete; };
low[] = Extrude {0, 0, t / 2} { Surface{5}; };
high[] = Extrude {0, 0, t / 2} { Surface{low[0]}; };
BooleanFragments{ Volume{low[1], high[1]}; Delete; }{}

e = 1e-6;
stop[] = Surface In BoundingBox {-e, -e, t / 2 - e, 4, 4, t / 2 + e};
sbot[] = Surface In BoundingBox {-e, -e, -t / 2 - e, 4, 4, -t / 2 + e};
smid[] = Surface In BoundingBox {-e, -e, -e, 4, 4, e};
sx0[] = Surface In BoundingBox {-e, -e, -t, e, 4, t};
sy0[] = Surface In BoundingBox {-e, -e, -t, 4, e, t};
sin[] = Surface In BoundingBox {-e, -e, -t, 2 + e, 1 + e, t};
sall[] = Surface In BoundingBox {-e, -e, -t, 4, 4, t};
sout[] = sall[];
sout[] -= {stop[], sbot[], smid[], sx0[], sy0[], sin[]};
cmid[] = Curve In BoundingBox {-e, -e, -e, 4, 4, e};
cmid[] -= {Curve In BoundingBox {-e, -e, -e, 2 + e, 1 + e, e}};
cmid[] -= {Curve In BoundingBox {-e, -e, -e, e, 4, e}};
cmid[] -= {Curve In BoundingBox {-e, -e, -e, 4, e, e}};
pD[] = Point In BoundingBox {2 - e, -e, t / 2 - e, 2 + e, e, t / 2 + e};

Field[1] = Distance;
Field[1].PointsList = {pD[0]};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = hD;
Field[2].SizeMax = h;
Field[2].DistMin = 2 * hD;
Field[2].DistMax = 1.2;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

Physical Volume("plate") = {Volume{:}};
Physical Surface("upper_face") = {stop[]};       // 1 MPa pressure
Physical Surface("y0_DCDC") = {sy0[]};           // u_y = 0
Physical Surface("x0_ABAB") = {sx0[]};           // u_x = 0
Physical Surface("outer_BCBC") = {sout[]};       // u_x = u_y = 0
Physical Curve("midline_EE") = {cmid[]};         // u_z = 0
Physical Point("target") = {pD[0]};              // D on the upper face
