// A surface-grinding machine's wheel head as a 2-D section (plane stress) through the wheel
// spindle, SI units (m). A cast wheel head on its slide carries the motor (left) and the
// spindle in its bearings; the wheel (right) overhangs and grinds the workpiece on the table
// below it, both flooded with coolant. δ: the wheel's lowest point
// against the workpiece along y (+ = wheel and workpiece approach: the cut deepens).
//
//   +---- slide ---------------------------------+
//   | motor |   head  [bearings] jacket   |====== spindle ====(wheel)
//   +-----------------------------------------+          |  wheel  |
//   |                column                |            .work.
//   |                                      |    +---------table---------+
//   +------------------- bed ------------------------------------------------+
//   +--F----------------------------------------------------------------S----+
//
// Named groups: regions bed, column, head, motor, bearings, spindle, wheel, table;
// boundaries coolant (flooded: the wheel and the table top), feet_fixed, feet_sliding, free; points wheel_low, work, T_head, T_column, T_bed.
SetFactory("OpenCASCADE");
If (!Exists(size)) size = 0.03; EndIf
If (!Exists(wheel_radius)) wheel_radius = 0.15; EndIf  // grinding wheel radius, m
R = wheel_radius;
ya = 1.05;                                              // spindle axis height, m

Rectangle(1) = {0.0, 0.0, 0, 1.6, 0.3};                 // bed
Rectangle(2) = {0.0, 0.3, 0, 0.45, 0.6};                // column
Rectangle(3) = {0.0, 0.9, 0, 0.8, 0.3};                 // wheel head casting (on its slide)
Rectangle(4) = {0.05, 0.95, 0, 0.2, 0.2};               // motor
Rectangle(5) = {0.55, ya - 0.07, 0, 0.15, 0.14};        // bearing cartridge
Rectangle(6) = {0.55, ya - 0.03, 0, 0.55, 0.06};        // spindle
Rectangle(7) = {1.0, ya - R, 0, 0.05, 2 * R};           // wheel (section through its width)
Rectangle(8) = {0.8, 0.3, 0, 0.6, 0.2};                 // table (with the workpiece)
Point(101) = {1.025, ya - R, 0};                        // wheel, lowest point
Point(102) = {1.025, 0.5, 0};                           // workpiece surface on the table
Point(103) = {0.625, 1.2, 0};                           // head top above the bearings
Point(104) = {0.45, 0.6, 0};                            // column front
Point(105) = {0.8, 0.0, 0};                             // bed underside
Point(106) = {0.2, 0.0, 0};                             // end of the fixed feet
Point(107) = {1.4, 0.0, 0};                             // start of the sliding feet
BooleanFragments{ Surface{1:8}; Point{101:107}; Delete; }{}

e = 1e-6;
sp[] = Surface In BoundingBox{0.55 - e, ya - 0.03 - e, -e, 1.1 + e, ya + 0.03 + e, e};
wh[] = Surface In BoundingBox{1.0 - e, ya - R - e, -e, 1.05 + e, ya + R + e, e};
sp[] -= {wh[]};
be[] = Surface In BoundingBox{0.55 - e, ya - 0.07 - e, -e, 0.7 + e, ya + 0.07 + e, e};
be[] -= {sp[]};
mo[] = Surface In BoundingBox{0.05 - e, 0.95 - e, -e, 0.25 + e, 1.15 + e, e};
hd[] = Surface In BoundingBox{-e, 0.9 - e, -e, 0.8 + e, 1.2 + e, e};
hd[] -= {mo[], be[], sp[]};
Physical Surface("bed") = Surface In BoundingBox{-e, -e, -e, 1.6 + e, 0.3 + e, e};
Physical Surface("column") = Surface In BoundingBox{-e, 0.3 - e, -e, 0.45 + e, 0.9 + e, e};
Physical Surface("head") = {hd[]};
Physical Surface("motor") = {mo[]};
Physical Surface("bearings") = {be[]};
Physical Surface("spindle") = {sp[]};
Physical Surface("wheel") = {wh[]};
Physical Surface("table") = Surface In BoundingBox{0.8 - e, 0.3 - e, -e, 1.4 + e, 0.5 + e, e};
fixed[] = Curve In BoundingBox{-e, -e, -e, 0.2 + e, e, e};
sliding[] = Curve In BoundingBox{1.4 - e, -e, -e, 1.6 + e, e, e};
outer[] = Abs(CombinedBoundary{ Surface{:}; });
wet[] = Curve In BoundingBox{0.95 - e, 0.5 - e, -e, 1.1 + e, ya + R + e, e};   // the wheel, flooded
wet[] += Curve In BoundingBox{0.8 - e, 0.5 - e, -e, 1.4 + e, 0.5 + e, e};     // and the table top
outer[] -= {fixed[], sliding[]};
wet[] = Unique(wet[]);
wet_outer[] = outer[];
wet_outer[] -= {wet[]};
wet[] = outer[];
wet[] -= {wet_outer[]};
outer[] = wet_outer[];
Physical Curve("feet_fixed") = {fixed[]};
Physical Curve("feet_sliding") = {sliding[]};
Physical Curve("free") = {outer[]};
Physical Curve("coolant") = {wet[]};
Physical Point("wheel_low") = Point In BoundingBox{1.025 - e, ya - R - e, -e, 1.025 + e, ya - R + e, e};
Physical Point("work") = Point In BoundingBox{1.025 - e, 0.5 - e, -e, 1.025 + e, 0.5 + e, e};
Physical Point("T_head") = Point In BoundingBox{0.625 - e, 1.2 - e, -e, 0.625 + e, 1.2 + e, e};
Physical Point("T_column") = Point In BoundingBox{0.45 - e, 0.6 - e, -e, 0.45 + e, 0.6 + e, e};
Physical Point("T_bed") = Point In BoundingBox{0.8 - e, -e, -e, 0.8 + e, e, e};
Mesh.MeshSizeMax = size;
