// A direct-drive rotary table as an axisymmetric section: x = r >= 0 (m), y the table's axis,
// SI units (m). A cast housing ring on the machine bed carries the torque motor's stator and
// the axial-radial bearing; the steel table plate (r = 0 .. 0.32 m) rides on the bearing.
// δ: the table top at the workpiece radius rising against the bed (+ = towards the tool above).
//
//   y
//   |========== table plate ===========|   (0 .. 0.32, 0.30 .. 0.36)
//   |   [bearing]        [stator]  |   |
//   |   housing ring (0.08 .. 0.34)    |
//   +------------- bed plate ----------------+
//   +--S-------------------------------------+  (held axially)
//   0 ---------------------------------------> x = r
//
// Named groups: regions bed, housing, stator, bearing, table; boundaries floor, free;
// points top, bed_ref, T_housing, T_table, T_bed.
SetFactory("OpenCASCADE");
If (!Exists(size)) size = 0.02; EndIf
If (!Exists(plate)) plate = 0.06; EndIf                  // table plate thickness, m

Rectangle(1) = {0.0, 0.0, 0, 0.5, 0.1};                  // bed plate under the table
Rectangle(2) = {0.08, 0.1, 0, 0.26, 0.2};                // housing ring
Rectangle(3) = {0.24, 0.14, 0, 0.06, 0.12};              // torque motor stator (in the housing)
Rectangle(4) = {0.1, 0.26, 0, 0.08, 0.04};               // axial-radial bearing (top of housing)
Rectangle(5) = {0.0, 0.3, 0, 0.32, plate};               // table plate
Point(101) = {0.25, 0.3 + plate, 0};                     // table top at the workpiece radius
Point(102) = {0.45, 0.1, 0};                             // bed top outside the housing
Point(103) = {0.34, 0.2, 0};                             // housing outside
Point(104) = {0.32, 0.3 + plate / 2, 0};                 // table rim
Point(105) = {0.45, 0.0, 0};                             // bed underside
BooleanFragments{ Surface{1:5}; Point{101:105}; Delete; }{}

e = 1e-6;
st[] = Surface In BoundingBox{0.24 - e, 0.14 - e, -e, 0.3 + e, 0.26 + e, e};
br[] = Surface In BoundingBox{0.1 - e, 0.26 - e, -e, 0.18 + e, 0.3 + e, e};
ho[] = Surface In BoundingBox{0.08 - e, 0.1 - e, -e, 0.34 + e, 0.3 + e, e};
ho[] -= {st[], br[]};
Physical Surface("bed") = Surface In BoundingBox{-e, -e, -e, 0.5 + e, 0.1 + e, e};
Physical Surface("housing") = {ho[]};
Physical Surface("stator") = {st[]};
Physical Surface("bearing") = {br[]};
Physical Surface("table") = Surface In BoundingBox{-e, 0.3 - e, -e, 0.32 + e, 0.3 + plate + e, e};
floor[] = Curve In BoundingBox{-e, -e, -e, 0.5 + e, e, e};
axis[] = Curve In BoundingBox{-e, -e, -e, e, 0.3 + plate + e, e};
outer[] = Abs(CombinedBoundary{ Surface{:}; });
outer[] -= {floor[], axis[]};
Physical Curve("floor") = {floor[]};
Physical Curve("free") = {outer[]};
Physical Point("top") = Point In BoundingBox{0.25 - e, 0.3 + plate - e, -e, 0.25 + e, 0.3 + plate + e, e};
Physical Point("bed_ref") = Point In BoundingBox{0.45 - e, 0.1 - e, -e, 0.45 + e, 0.1 + e, e};
Physical Point("T_housing") = Point In BoundingBox{0.34 - e, 0.2 - e, -e, 0.34 + e, 0.2 + e, e};
Physical Point("T_table") = Point In BoundingBox{0.32 - e, 0.3 + plate / 2 - e, -e, 0.32 + e, 0.3 + plate / 2 + e, e};
Physical Point("T_bed") = Point In BoundingBox{0.45 - e, -e, -e, 0.45 + e, e, e};
Mesh.MeshSizeMax = size;
