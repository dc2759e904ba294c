// NAFEMS LE11 "Solid cylinder/taper/sphere - temperature" (TNSB Rev. 3, 1990).
// Hollow body of revolution about the z axis, modelled here as a 3-D solid QUARTER
// (0 <= theta <= 90 deg, x >= 0, y >= 0) with the two cut planes as symmetry planes.
// SI units (m).  Meridian (r, z), NAFEMS point labels:
//
//   H (0.7071, 1.79) ---- I (1.0, 1.79)        top annulus HIH'I' : u_z = 0
//   |  cylinder            |
//   |                      G (1.0, 1.39)
//   |                       \   taper (straight D-G, F = mid point (1.1062, 1.045))
//   |                        \
//   E (0.7071, 0.7071)        D (1.2124, 0.7)  (outer sphere r = 1.4 at 30 deg)
//    \  inner sphere r = 1.0   |
//     C (0.9239, 0.3827)       |  outer sphere r = 1.4
//       \                      |
//        A (1.0, 0) ---------- B (1.4, 0)      base annulus ABA'B' : u_z = 0
//
// Temperature T = sqrt(x^2 + y^2) + z  [C, with x, y, z in m], stress free at T = 0.
// E = 210 GPa, nu = 0.3, alpha = 2.3e-4 /C.  Target: sigma_zz at A = (1, 0, 0) = -105 MPa.
//
// The junction heights follow the NAFEMS point table as reproduced in FinEALE
// (D at z = 0.7, G at z = 1.39, top at z = 1.79); FeenoX instead puts D at
// z = sin(45 deg) = 0.7071 (top at 1.7971).  Set zD = Sin(Pi/4) to get that variant.

SetFactory("OpenCASCADE");

If (!Exists(h))  h  = 0.15;   EndIf   // element size away from A
If (!Exists(hA)) hA = h / 6;  EndIf   // element size at A
If (!Exists(zD)) zD = 0.7;    EndIf   // height of the outer sphere / taper junction D

Ri = 1.0;  Ro = 1.4;                  // inner and outer sphere radii
rc = 1.0 / Sqrt(2);                   // inner cylinder radius 0.7071 (E on the unit sphere)
zG = zD + 0.345 + 0.345;              // taper top G
zI = zG + 0.400;                      // top face

Point(1) = {0, 0, 0};                         // O, centre of both spheres
Point(2) = {Ri, 0, 0};                        // A  (target)
Point(3) = {Ro, 0, 0};                        // B
Point(4) = {Sqrt(Ro^2 - zD^2), 0, zD};        // D
Point(5) = {1.0, 0, zG};                      // G
Point(6) = {1.0, 0, zI};                      // I
Point(7) = {rc, 0, zI};                       // H
Point(8) = {rc, 0, rc};                       // E

Line(1) = {2, 3};          // A-B base
Circle(2) = {3, 1, 4};     // B-D outer sphere
Line(3) = {4, 5};          // D-G taper
Line(4) = {5, 6};          // G-I outer cylinder
Line(5) = {6, 7};          // I-H top
Line(6) = {7, 8};          // H-E inner cylinder
Circle(7) = {8, 1, 2};     // E-A inner sphere

Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7};
Plane Surface(1) = {1};    // meridian section in the plane y = 0

out[] = Extrude {{0, 0, 1}, {0, 0, 0}, Pi/2} { Surface{1}; };
vol = out[1];

e = 1e-6;
sy0[] = Surface In BoundingBox {-e, -e, -e, 2, e, 2};          // plane y = 0
sx0[] = Surface In BoundingBox {-e, -e, -e, e, 2, 2};          // plane x = 0
sbase[] = Surface In BoundingBox {-2, -2, -e, 2, 2, e};        // z = 0 annulus (ABA'B')
stop[] = Surface In BoundingBox {-2, -2, zI - e, 2, 2, zI + e};  // top annulus (HIH'I')
sfree[] = Abs(Boundary{ Volume{vol}; });
sfree[] -= {sy0[], sx0[], sbase[], stop[]};
pA[] = Point In BoundingBox {Ri - e, -e, -e, Ri + e, e, e};

// Local refinement around A (the stress is read there).
Field[1] = Distance;
Field[1].PointsList = {pA[0]};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = hA;
Field[2].SizeMax = h;
Field[2].DistMin = 2 * hA;
Field[2].DistMax = 0.6;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

Physical Volume("solid") = {vol};
Physical Surface("y0_symmetry") = {sy0[]};      // u_y = 0
Physical Surface("x0_symmetry") = {sx0[]};      // u_x = 0
Physical Surface("base_ABAB") = {sbase[]};      // u_z = 0  (face ABA'B')
Physical Surface("top_HIHI") = {stop[]};        // u_z = 0  (face HIH'I')
Physical Surface("free") = {sfree[]};           // traction free
Physical Point("target") = {pA[0]};             // A
