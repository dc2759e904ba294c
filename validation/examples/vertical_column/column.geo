// A vertical machining centre's travelling column with its moving spindle head, as a 2-D
// section (plane stress) in the x-y plane, SI units (m). The column stands on the base (bolted:
// the interface base/column is a joint in the case); the spindle head (a heavy slide with its
// motor) sits on the column's front at height head_height, which the case sweeps; its spindle
// points down at the workpiece on the base's table area.
//
//        +--+
//        |  |-------+
//        |c |  head |   (at head_height)
//        |o |---+---+
//        |l |   |spindle
//        |  |   T (tool)
//        |  |   w (workpiece on the base)
//   +----+--+-----------------+
//   |          base           |
//   +--F-------------------S--+
//
// Named groups: regions base, column, head, spindle; boundaries base/column (the joint),
// feet_fixed, feet_sliding, free; points tool, work, T_head, T_front, T_back.
SetFactory("OpenCASCADE");
If (!Exists(size)) size = 0.04; EndIf
If (!Exists(head_height)) head_height = 1.1; EndIf      // bottom of the head above the floor, m
hh = head_height;

Rectangle(1) = {0.0, 0.0, 0, 1.5, 0.35};                // base (with the table area on top)
Rectangle(2) = {0.1, 0.35, 0, 0.4, 1.65};               // column
Rectangle(3) = {0.5, hh, 0, 0.45, 0.45};                // spindle head (slide, motor)
Rectangle(4) = {0.68, hh - 0.25, 0, 0.12, 0.25};        // spindle quill below the head
Point(101) = {0.74, hh - 0.25, 0};                      // tool (spindle nose)
Point(102) = {0.74, 0.35, 0};                           // workpiece on the base
Point(103) = {0.95, hh + 0.3, 0};                       // head front
Point(104) = {0.5, 1.0, 0};                             // column front
Point(105) = {0.1, 1.0, 0};                             // column back
Point(106) = {0.3, 0.0, 0};                             // end of the fixed feet
Point(107) = {1.2, 0.0, 0};                             // start of the sliding feet
BooleanFragments{ Surface{1:4}; Point{101:107}; Delete; }{}

e = 1e-6;
Physical Surface("base") = Surface In BoundingBox{-e, -e, -e, 1.5 + e, 0.35 + e, e};
Physical Surface("column") = Surface In BoundingBox{0.1 - e, 0.35 - e, -e, 0.5 + e, 2.0 + e, e};
Physical Surface("head") = Surface In BoundingBox{0.5 - e, hh - e, -e, 0.95 + e, hh + 0.45 + e, e};
Physical Surface("spindle") = Surface In BoundingBox{0.68 - e, hh - 0.25 - e, -e, 0.8 + e, hh + e, e};
Physical Curve("base/column") = Curve In BoundingBox{0.1 - e, 0.35 - e, -e, 0.5 + e, 0.35 + e, e};
fixed[] = Curve In BoundingBox{-e, -e, -e, 0.3 + e, e, e};
sliding[] = Curve In BoundingBox{1.2 - e, -e, -e, 1.5 + e, e, e};
outer[] = Abs(CombinedBoundary{ Surface{:}; });
outer[] -= {fixed[], sliding[]};
Physical Curve("feet_fixed") = {fixed[]};
Physical Curve("feet_sliding") = {sliding[]};
Physical Curve("free") = {outer[]};
Physical Point("tool") = Point In BoundingBox{0.74 - e, hh - 0.25 - e, -e, 0.74 + e, hh - 0.25 + e, e};
Physical Point("work") = Point In BoundingBox{0.74 - e, 0.35 - e, -e, 0.74 + e, 0.35 + e, e};
Physical Point("T_head") = Point In BoundingBox{0.95 - e, hh + 0.3 - e, -e, 0.95 + e, hh + 0.3 + e, e};
Physical Point("T_front") = Point In BoundingBox{0.5 - e, 1.0 - e, -e, 0.5 + e, 1.0 + e, e};
Physical Point("T_back") = Point In BoundingBox{0.1 - e, 1.0 - e, -e, 0.1 + e, 1.0 + e, e};
Mesh.MeshSizeMax = size;
