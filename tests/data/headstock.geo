// A lathe headstock as a 2-D section along the spindle axis (x-y plane, SI units, m): a cast
// housing on a bed, the spindle in a bore of the housing, held by a front and a rear bearing
// (above and below the spindle in the section). The bore is open at the front; the spindle nose
// stands out of it.
//
//            +--------------------------------+ housing (0.15..0.75 x 0.15..0.55)
//            |                                |
//            | +--R----------------------F--+ |        R, F: rear and front bearings
//            | |  ===========spindle============ nose   spindle 0.24..0.90 x 0.33..0.39
//            | +--R----------------------F--+ |
//   +--------+--------------------------------+------------+
//   |                         bed                    carriage  (0..1.0 x 0..0.15)
//   +--FF--------------------------------------------SS----+  feet: fixed / sliding
//
// Named groups: regions bed, housing, spindle, bearing_front, bearing_rear; boundaries
// feet_fixed, feet_sliding, free (every other outer edge, the bore's included).
SetFactory("OpenCASCADE");
If (!Exists(size)) size = 0.02; EndIf
Rectangle(1) = {0.0, 0.0, 0, 1.0, 0.15};       // bed
Rectangle(2) = {0.15, 0.15, 0, 0.6, 0.40};     // housing block
Rectangle(3) = {0.20, 0.30, 0, 0.55, 0.12};    // its bore, open at the front
BooleanDifference(10) = { Surface{2}; Delete; }{ Surface{3}; Delete; };
Rectangle(4) = {0.24, 0.33, 0, 0.66, 0.06};    // spindle
Rectangle(5) = {0.64, 0.30, 0, 0.08, 0.03};    // front bearing, below and above
Rectangle(6) = {0.64, 0.39, 0, 0.08, 0.03};
Rectangle(7) = {0.28, 0.30, 0, 0.06, 0.03};    // rear bearing, below and above
Rectangle(8) = {0.28, 0.39, 0, 0.06, 0.03};
Point(101) = {0.15, 0.0, 0};                   // end of the fixed feet
Point(102) = {0.85, 0.0, 0};                   // start of the sliding feet
Point(103) = {0.90, 0.36, 0};                  // spindle nose, on the axis
Point(104) = {0.90, 0.15, 0};                  // carriage (the tool's seat on the bed)
BooleanFragments{ Surface{1, 10, 4:8}; Point{101:104}; Delete; }{}

e = 1e-6;
bed[] = Surface In BoundingBox{-e, -e, -e, 1.0 + e, 0.15 + e, e};
front[] = Surface In BoundingBox{0.64 - e, 0.30 - e, -e, 0.72 + e, 0.42 + e, e};
rear[] = Surface In BoundingBox{0.28 - e, 0.30 - e, -e, 0.34 + e, 0.42 + e, e};
spindle[] = Surface In BoundingBox{0.24 - e, 0.33 - e, -e, 0.90 + e, 0.39 + e, e};
housing[] = Surface In BoundingBox{0.15 - e, 0.15 - e, -e, 0.75 + e, 0.55 + e, e};
housing[] -= {front[], rear[], spindle[]};
Physical Surface("bed") = {bed[]};
Physical Surface("housing") = {housing[]};
Physical Surface("spindle") = {spindle[]};
Physical Surface("bearing_front") = {front[]};
Physical Surface("bearing_rear") = {rear[]};
fixed[] = Curve In BoundingBox{-e, -e, -e, 0.15 + e, e, e};
sliding[] = Curve In BoundingBox{0.85 - e, -e, -e, 1.0 + e, e, e};
outer[] = Abs(CombinedBoundary{ Surface{:}; });
outer[] -= {fixed[], sliding[]};
Physical Curve("feet_fixed") = {fixed[]};
Physical Curve("feet_sliding") = {sliding[]};
Physical Curve("free") = {outer[]};
Physical Point("nose") = Point In BoundingBox{0.90 - e, 0.36 - e, -e, 0.90 + e, 0.36 + e, e};
Physical Point("carriage") = Point In BoundingBox{0.90 - e, 0.15 - e, -e, 0.90 + e, 0.15 + e, e};
Mesh.MeshSizeMax = size;
