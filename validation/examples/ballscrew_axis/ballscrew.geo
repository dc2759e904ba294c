// A ball-screw feed axis as a 2-D section (plane stress) through the screw axis, SI units (m).
// The steel screw (1.2 m, 40 mm) runs in a fixed bearing block at the motor end and a floating
// support block at the other; the nut (with the table on it, mid-stroke) heats the screw by
// friction, the fixed bearing and the motor flange add their losses. Tool-side δ: the nut's
// (table's) position error along x against the scale read head on the bed.
//
//   motor|fixed bearing|======== screw ======[nut+table]========|support block|
//   +------------------------------ bed -----------------------------------------+
//   +--F----------------------------------------------------------------------S--+
//
// Named groups: regions bed, motor, bearing_block, support_block, screw, nut;
// boundaries feet_fixed, feet_sliding, free; points table, scale, T_nut, T_bearing, T_bed.
SetFactory("OpenCASCADE");
If (!Exists(size)) size = 0.03; EndIf
If (!Exists(nut_position)) nut_position = 0.75; EndIf   // nut centre along the screw, m
hs = 0.2;                                               // screw axis above the bed top, m
y0 = 0.12;                                              // bed top, m
rs = 0.02;                                              // screw radius, m

Rectangle(1) = {0.0, 0.0, 0, 1.6, y0};                  // bed
Rectangle(2) = {0.0, y0, 0, 0.14, 0.16};                // motor (flange on the bearing block)
Rectangle(3) = {0.14, y0, 0, 0.1, hs + 0.06};           // fixed bearing block
Rectangle(4) = {1.36, y0, 0, 0.08, hs + 0.05};          // floating support block
Rectangle(5) = {0.24, y0 + hs - rs, 0, 1.12, 2 * rs};   // screw between the blocks
Rectangle(6) = {nut_position - 0.06, y0 + hs + rs, 0, 0.12, 0.05};  // nut and table, on the screw
Point(101) = {nut_position, y0 + hs + rs + 0.05, 0};    // table top (the workpiece side)
Point(102) = {nut_position, y0, 0};                     // scale read head on the bed below the nut
Point(103) = {nut_position + 0.06, y0 + hs + rs + 0.025, 0};  // nut flange thermocouple
Point(104) = {0.19, y0 + hs + 0.06, 0};                 // bearing block top
Point(105) = {0.8, 0.0, 0};                             // bed underside mid
Point(106) = {0.2, 0.0, 0};                             // end of the fixed feet
Point(107) = {1.4, 0.0, 0};                             // start of the sliding feet
BooleanFragments{ Surface{1:6}; Point{101:107}; Delete; }{}

e = 1e-6;
Physical Surface("bed") = Surface In BoundingBox{-e, -e, -e, 1.6 + e, y0 + e, e};
Physical Surface("motor") = Surface In BoundingBox{-e, y0 - e, -e, 0.14 + e, y0 + 0.16 + e, e};
Physical Surface("bearing_block") = Surface In BoundingBox{0.14 - e, y0 - e, -e, 0.24 + e, y0 + hs + 0.06 + e, e};
Physical Surface("support_block") = Surface In BoundingBox{1.36 - e, y0 - e, -e, 1.44 + e, y0 + hs + 0.05 + e, e};
Physical Surface("screw") = Surface In BoundingBox{0.24 - e, y0 + hs - rs - e, -e, 1.36 + e, y0 + hs + rs + e, e};
Physical Surface("nut") = Surface In BoundingBox{nut_position - 0.06 - e, y0 + hs + rs - e, -e, nut_position + 0.06 + e, y0 + hs + rs + 0.05 + e, e};
fixed[] = Curve In BoundingBox{-e, -e, -e, 0.2 + e, e, e};
sliding[] = Curve In BoundingBox{1.4 - e, -e, -e, 1.6 + e, e, e};
outer[] = Abs(CombinedBoundary{ Surface{:}; });
outer[] -= {fixed[], sliding[]};
Physical Curve("feet_fixed") = {fixed[]};
Physical Curve("feet_sliding") = {sliding[]};
Physical Curve("free") = {outer[]};
Physical Point("table") = Point In BoundingBox{nut_position - e, y0 + hs + rs + 0.05 - e, -e, nut_position + e, y0 + hs + rs + 0.05 + e, e};
Physical Point("scale") = Point In BoundingBox{nut_position - e, y0 - e, -e, nut_position + e, y0 + e, e};
Physical Point("T_nut") = Point In BoundingBox{nut_position + 0.06 - e, y0 + hs + rs + 0.025 - e, -e, nut_position + 0.06 + e, y0 + hs + rs + 0.025 + e, e};
Physical Point("T_bearing") = Point In BoundingBox{0.19 - e, y0 + hs + 0.06 - e, -e, 0.19 + e, y0 + hs + 0.06 + e, e};
Physical Point("T_bed") = Point In BoundingBox{0.8 - e, -e, -e, 0.8 + e, e, e};
Mesh.MeshSizeMax = size;
