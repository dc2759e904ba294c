// A lathe headstock as a 2-D section (plane stress) in the x-y plane through the spindle axis,
// SI units (m). The cast housing stands on the bed; the spindle runs in a front (nose side)
// and a rear bearing, each drawn as its two rings above and below the spindle. The tool sits
// on a carriage on the bed, facing the spindle nose.
//
//            +---------------- housing ----------------+
//            |  [rear]                        [front]  |
//            |=====================spindle================|nose   tool|carriage|
//            |  [rear]                        [front]  |
//   +--------+-----------------------------------------+-----------+--------+-----+
//   |                                 bed                                          |
//   +--F--------------------------------------------------------------------S-----+
//
// Named groups: regions bed, housing, spindle, bearing_front, bearing_rear, carriage;
// boundaries feet_fixed, feet_sliding, free; points nose, tool, T_front, T_rear, T_bed.
SetFactory("OpenCASCADE");
If (!Exists(size)) size = 0.03; EndIf
If (!Exists(axis_height)) axis_height = 0.55; EndIf     // spindle axis above the floor, m
a = axis_height;
r = 0.04;                                               // spindle radius, m

Rectangle(1) = {0.0, 0.0, 0, 1.4, 0.3};                  // bed
Rectangle(2) = {0.1, 0.3, 0, 0.6, a + 0.2 - 0.3};        // housing
Rectangle(3) = {0.12, a - r, 0, 0.7, 2 * r};             // spindle (nose at x = 0.82)
Rectangle(4) = {0.58, a - r - 0.035, 0, 0.07, 0.035};    // front bearing, lower ring
Rectangle(5) = {0.58, a + r, 0, 0.07, 0.035};            // front bearing, upper ring
Rectangle(6) = {0.18, a - r - 0.03, 0, 0.06, 0.03};      // rear bearing, lower ring
Rectangle(7) = {0.18, a + r, 0, 0.06, 0.03};             // rear bearing, upper ring
Rectangle(8) = {0.87, 0.3, 0, 0.25, a - 0.3};            // carriage with the tool post
Point(101) = {0.82, a, 0};                               // spindle nose (the workpiece)
Point(102) = {0.87, a, 0};                               // tool tip
Point(103) = {0.615, a + 0.2, 0};                        // housing top above the front bearing
Point(104) = {0.21, a + 0.2, 0};                         // housing top above the rear bearing
Point(105) = {0.4, 0.0, 0};                              // bed, underside mid
Point(106) = {0.2, 0.0, 0};                              // end of the fixed feet
Point(107) = {1.2, 0.0, 0};                              // start of the sliding feet
BooleanFragments{ Surface{1:8}; Point{101:107}; Delete; }{}

e = 1e-6;
bf[] = Surface In BoundingBox{0.58 - e, a - r - 0.035 - e, -e, 0.65 + e, a + r + 0.035 + e, e};
br[] = Surface In BoundingBox{0.18 - e, a - r - 0.03 - e, -e, 0.24 + e, a + r + 0.03 + e, e};
sp[] = Surface In BoundingBox{0.12 - e, a - r - e, -e, 0.82 + e, a + r + e, e};
bf[] -= {sp[]};
br[] -= {sp[]};
ho[] = Surface In BoundingBox{0.1 - e, 0.3 - e, -e, 0.7 + e, a + 0.2 + e, e};
ho[] -= {sp[], bf[], br[]};
Physical Surface("bed") = Surface In BoundingBox{-e, -e, -e, 1.4 + e, 0.3 + e, e};
Physical Surface("housing") = {ho[]};
Physical Surface("spindle") = {sp[]};
Physical Surface("bearing_front") = {bf[]};
Physical Surface("bearing_rear") = {br[]};
Physical Surface("carriage") = Surface In BoundingBox{0.87 - e, 0.3 - e, -e, 1.12 + e, a + e, e};
fixed[] = Curve In BoundingBox{-e, -e, -e, 0.2 + e, e, e};
sliding[] = Curve In BoundingBox{1.2 - e, -e, -e, 1.4 + e, e, e};
outer[] = Abs(CombinedBoundary{ Surface{:}; });
outer[] -= {fixed[], sliding[]};
Physical Curve("feet_fixed") = {fixed[]};
Physical Curve("feet_sliding") = {sliding[]};
Physical Curve("free") = {outer[]};
Physical Point("nose") = Point In BoundingBox{0.82 - e, a - e, -e, 0.82 + e, a + e, e};
Physical Point("tool") = Point In BoundingBox{0.87 - e, a - e, -e, 0.87 + e, a + e, e};
Physical Point("T_front") = Point In BoundingBox{0.615 - e, a + 0.2 - e, -e, 0.615 + e, a + 0.2 + e, e};
Physical Point("T_rear") = Point In BoundingBox{0.21 - e, a + 0.2 - e, -e, 0.21 + e, a + 0.2 + e, e};
Physical Point("T_bed") = Point In BoundingBox{0.4 - e, -e, -e, 0.4 + e, e, e};
Mesh.MeshSizeMax = size;
