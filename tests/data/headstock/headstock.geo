// A lathe headstock as a 2-D section in the x-y plane, SI units (m): a cast housing on a bed,
// the spindle's front and rear bearings heating the housing. A small test machine, neither the
// paper's frame nor the C-frame (tests/test_benefit.py).
//
//        +---------------------+  housing (0.9..1.4 x 0.25..0.55)
//        |  [rear]    [front] T|  bearings; T = spindle nose (tool)
//        +---------------------+
//   +-------------------------------+  bed (0 .. 1.6 x 0 .. 0.25), clamped feet below
//
// Named groups: regions bed, housing, bearing_front, bearing_rear; boundaries feet, free;
// points tool, TH (housing top), TR (housing rear face), TB (the bed's far end; the carriage
// point, the bed top beside the housing at (1.55, 0.25), is given by coordinates in the case).
SetFactory("OpenCASCADE");
If (!Exists(size)) size = 0.04; EndIf
Rectangle(1) = {0.0, 0.0, 0, 1.6, 0.25};      // bed
Rectangle(2) = {0.9, 0.25, 0, 0.5, 0.3};      // housing
Rectangle(3) = {1.25, 0.36, 0, 0.08, 0.08};   // front bearing
Rectangle(4) = {0.97, 0.36, 0, 0.08, 0.08};   // rear bearing
Point(101) = {1.4, 0.40, 0};                  // tool: the spindle nose
Point(103) = {1.15, 0.55, 0};                 // TH: housing top
Point(104) = {0.9, 0.40, 0};                  // TR: housing rear face
Point(105) = {0.05, 0.05, 0};                 // TB: far end of the bed
BooleanFragments{ Surface{1:4}; Point{101, 103:105}; Delete; }{}

e = 1e-6;
Physical Surface("bed") = Surface In BoundingBox{-e, -e, -e, 1.6 + e, 0.25 + e, e};
Physical Surface("bearing_front") = Surface In BoundingBox{1.25 - e, 0.36 - e, -e, 1.33 + e, 0.44 + e, e};
Physical Surface("bearing_rear") = Surface In BoundingBox{0.97 - e, 0.36 - e, -e, 1.05 + e, 0.44 + e, e};
all[] = Surface In BoundingBox{0.9 - e, 0.25 - e, -e, 1.4 + e, 0.55 + e, e};
all[] -= {Surface In BoundingBox{1.25 - e, 0.36 - e, -e, 1.33 + e, 0.44 + e, e}};
all[] -= {Surface In BoundingBox{0.97 - e, 0.36 - e, -e, 1.05 + e, 0.44 + e, e}};
Physical Surface("housing") = {all[]};
feet[] = Curve In BoundingBox{-e, -e, -e, 1.6 + e, e, e};
outer[] = Abs(CombinedBoundary{ Surface{:}; });
outer[] -= {feet[]};
Physical Curve("feet") = {feet[]};
Physical Curve("free") = {outer[]};
Physical Point("tool") = Point In BoundingBox{1.4 - e, 0.40 - e, -e, 1.4 + e, 0.40 + e, e};
Physical Point("TH") = Point In BoundingBox{1.15 - e, 0.55 - e, -e, 1.15 + e, 0.55 + e, e};
Physical Point("TR") = Point In BoundingBox{0.9 - e, 0.40 - e, -e, 0.9 + e, 0.40 + e, e};
Physical Point("TB") = Point In BoundingBox{0.05 - e, 0.05 - e, -e, 0.05 + e, 0.05 + e, e};
Mesh.MeshSizeMax = size;
