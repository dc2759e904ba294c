// A C-frame machine (vertical machining centre) as a 2-D section in the x-y plane, SI units (m).
//
//          arm (1.2..1.5)
//   +----+===================+
//   |    |                   |         spindle housing hangs from the arm;
//   | c  |              +----+         tool = centre of the spindle nose,
//   | o  |              |spin|         table point = centre of the table top.
//   | l  |              +-T--+  (tool)
//   | u  |
//   | m  |           +---t---+ table (0.25..0.35)
//   +----+-----------+-------+------+
//   |              base             |
//   +--F-------------------------S--+   F: fixed feet, S: sliding feet
//
// Named groups: regions base, column, arm, spindle, table; boundaries feet_fixed,
// feet_sliding, free; points tool, table_top, TS (spindle housing), TF/TB (column front/back).
SetFactory("OpenCASCADE");
If (!Exists(size)) size = 0.03; EndIf
If (!Exists(table_height)) table_height = 0.1; EndIf   // thickness of the table, m
If (!Exists(spindle_length)) spindle_length = 0.35; EndIf  // spindle housing below the arm, m
top = 0.25 + table_height;                              // the table top (the workpiece), m
nose = 1.2 - spindle_length;                            // the spindle nose (the tool), m

Rectangle(1) = {0.0, 0.0, 0, 1.2, 0.25};     // base
Rectangle(2) = {0.0, 0.25, 0, 0.3, 1.25};    // column
Rectangle(3) = {0.3, 1.2, 0, 0.7, 0.3};      // arm
Rectangle(4) = {0.75, nose, 0, 0.2, spindle_length};  // spindle housing
Rectangle(5) = {0.65, 0.25, 0, 0.4, table_height};  // table
Point(101) = {0.85, nose, 0};                // tool
Point(102) = {0.85, top, 0};                 // table top
Point(103) = {0.95, 1.0, 0};                 // spindle housing thermocouple
Point(104) = {0.3, 0.8, 0};                  // column front face
Point(105) = {0.0, 0.8, 0};                  // column back face
Point(106) = {0.2, 0.0, 0};                  // end of the fixed feet
Point(107) = {1.0, 0.0, 0};                  // start of the sliding feet
BooleanFragments{ Surface{1:5}; Point{101:107}; Delete; }{}

e = 1e-6;
Physical Surface("base") = Surface In BoundingBox{-e, -e, -e, 1.2 + e, 0.25 + e, e};
Physical Surface("column") = Surface In BoundingBox{-e, 0.25 - e, -e, 0.3 + e, 1.5 + e, e};
Physical Surface("arm") = Surface In BoundingBox{0.3 - e, 1.2 - e, -e, 1.0 + e, 1.5 + e, e};
Physical Surface("spindle") = Surface In BoundingBox{0.75 - e, nose - e, -e, 0.95 + e, 1.2 + e, e};
Physical Surface("table") = Surface In BoundingBox{0.65 - e, 0.25 - e, -e, 1.05 + e, top + e, e};
fixed[] = Curve In BoundingBox{-e, -e, -e, 0.2 + e, e, e};
sliding[] = Curve In BoundingBox{1.0 - e, -e, -e, 1.2 + e, e, e};
outer[] = Abs(CombinedBoundary{ Surface{:}; });
outer[] -= {fixed[], sliding[]};
Physical Curve("feet_fixed") = {fixed[]};
Physical Curve("feet_sliding") = {sliding[]};
Physical Curve("free") = {outer[]};
Physical Point("tool") = Point In BoundingBox{0.85 - e, nose - e, -e, 0.85 + e, nose + e, e};
Physical Point("table_top") = Point In BoundingBox{0.85 - e, top - e, -e, 0.85 + e, top + e, e};
Physical Point("TS") = Point In BoundingBox{0.95 - e, 1.0 - e, -e, 0.95 + e, 1.0 + e, e};
Physical Point("TF") = Point In BoundingBox{0.3 - e, 0.8 - e, -e, 0.3 + e, 0.8 + e, e};
Physical Point("TB") = Point In BoundingBox{-e, 0.8 - e, -e, e, 0.8 + e, e};
Mesh.MeshSizeMax = size;
