// NAFEMS T1 "Membrane with hot-spot" (TNSB Rev. 3, 1990): linear thermo-elastic,
// plane stress.  Quarter model of a 20 mm x 20 mm square membrane with a circular
// hot spot of radius 1 mm at its centre.  SI units (m).
//
//   y
//   |  Dp ------------------------- C      x = 0 : u_x = 0 ("x0_symmetry")
//   |  |                            |      y = 0 : u_y = 0 ("y0_symmetry")
//   |  |          plate             |      x = L, y = L : traction free ("free_edge")
//   |  P                            |      hot spot  : alpha*T = 1e-3 (T = 100 C)
//   |  |  hot_spot                  |      plate     : alpha*T = 0     (T = 0 C)
//   |  O --- D -------------------- B --> x
//
// Target: sigma_yy at D = (a, 0), read on the plate side (outside the hot spot) = 50 MPa.
// Sizes can be overridden before parsing, e.g. gmsh.parser.setNumber("h", [5e-4]).

If (!Exists(a))  a  = 1.0e-3; EndIf    // hot-spot radius
If (!Exists(L))  L  = 10.0e-3; EndIf   // half side of the square membrane
If (!Exists(h))  h  = 1.0e-3; EndIf    // element size far from the hot spot
If (!Exists(hD)) hD = h / 8; EndIf     // element size along the hot-spot edge

Point(1) = {0, 0, 0, hD};   // O, hot-spot centre
Point(2) = {a, 0, 0, hD};   // D, target point (edge of the hot spot on the x axis)
Point(3) = {0, a, 0, hD};   // P, edge of the hot spot on the y axis
Point(4) = {L, 0, 0, h};    // B
Point(5) = {L, L, 0, h};    // C
Point(6) = {0, L, 0, h};    // Dp

Line(1) = {1, 2};           // O-D   (y = 0, inside the hot spot)
Circle(2) = {2, 1, 3};      // D-P   hot-spot edge (material interface)
Line(3) = {3, 1};           // P-O   (x = 0, inside the hot spot)
Line(4) = {2, 4};           // D-B   (y = 0, outside)
Line(5) = {4, 5};           // B-C   (x = L)
Line(6) = {5, 6};           // C-Dp  (y = L)
Line(7) = {6, 3};           // Dp-P  (x = 0, outside)

Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};                 // hot spot
Curve Loop(2) = {4, 5, 6, 7, -2};
Plane Surface(2) = {2};                 // rest of the membrane

// Refine towards the hot-spot edge (the stress jumps across it) and point D.
Field[1] = Distance;
Field[1].CurvesList = {2};
Field[1].Sampling = 200;
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = hD;
Field[2].SizeMax = h;
Field[2].DistMin = 0.5 * a;
Field[2].DistMax = 4 * a;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;

Physical Surface("hot_spot") = {1};
Physical Surface("plate") = {2};
Physical Curve("x0_symmetry") = {3, 7};
Physical Curve("y0_symmetry") = {1, 4};
Physical Curve("free_edge") = {5, 6};
Physical Curve("hot_spot_edge") = {2};  // interface, no condition; named for post-processing
Physical Point("target") = {2};          // D
