// A lathe headstock as a 2-D section through the spindle axis (a machine other than the
// shipped two, for the diagnosis tests): a cast housing on a bed, a steel spindle in the
// housing's bore, held by a front and a rear bearing (above and below the spindle in the
// section). Between the bearings the bore is an air gap, so the spindle touches the
// housing only through the bearings. Sizes can be set before parsing (h).
SetFactory("OpenCASCADE");
If (!Exists(h)) h = 0.02; EndIf
Rectangle(1) = {0, 0, 0, 0.8, 0.15};                  // bed
Rectangle(2) = {0.1, 0.15, 0, 0.5, 0.3};              // housing ...
Rectangle(3) = {0.14, 0.27, 0, 0.46, 0.1};            // ... less its bore, open at the front
BooleanDifference(4) = { Surface{2}; Delete; }{ Surface{3}; Delete; };
Rectangle(5) = {0.16, 0.29, 0, 0.54, 0.06};           // spindle, nose at x = 0.7
Rectangle(6) = {0.18, 0.27, 0, 0.06, 0.02};           // rear bearing, below and above
Rectangle(7) = {0.18, 0.35, 0, 0.06, 0.02};
Rectangle(8) = {0.5, 0.27, 0, 0.06, 0.02};            // front bearing
Rectangle(9) = {0.5, 0.35, 0, 0.06, 0.02};
BooleanFragments{ Surface{1, 4}; Delete; }{ Surface{5, 6, 7, 8, 9}; Delete; }
e = 1e-6;
bed[] = Surface In BoundingBox {-e, -e, -e, 0.8 + e, 0.15 + e, e};
house[] = Surface In BoundingBox {0.1 - e, 0.15 - e, -e, 0.6 + e, 0.45 + e, e};
spin[] = Surface In BoundingBox {0.16 - e, 0.29 - e, -e, 0.7 + e, 0.35 + e, e};
rear[] = Surface In BoundingBox {0.18 - e, 0.27 - e, -e, 0.24 + e, 0.29 + e, e};
rear[] += Surface In BoundingBox {0.18 - e, 0.35 - e, -e, 0.24 + e, 0.37 + e, e};
front[] = Surface In BoundingBox {0.5 - e, 0.27 - e, -e, 0.56 + e, 0.29 + e, e};
front[] += Surface In BoundingBox {0.5 - e, 0.35 - e, -e, 0.56 + e, 0.37 + e, e};
house[] -= {spin[], rear[], front[]};
Physical Surface("bed") = {bed[]};
Physical Surface("housing") = {house[]};
Physical Surface("spindle") = {spin[]};
Physical Surface("bearing_rear") = {rear[]};
Physical Surface("bearing_front") = {front[]};
// the bearings' inner rings on the spindle (y = 0.29 and 0.35), outer rings in the housing
rs[] = Curve In BoundingBox {0.18 - e, 0.29 - e, -e, 0.24 + e, 0.29 + e, e};
rs[] += Curve In BoundingBox {0.18 - e, 0.35 - e, -e, 0.24 + e, 0.35 + e, e};
fs[] = Curve In BoundingBox {0.5 - e, 0.29 - e, -e, 0.56 + e, 0.29 + e, e};
fs[] += Curve In BoundingBox {0.5 - e, 0.35 - e, -e, 0.56 + e, 0.35 + e, e};
Physical Curve("bearing_rear/spindle") = {rs[]};
Physical Curve("bearing_front/spindle") = {fs[]};
feet[] = Curve In BoundingBox {-e, -e, -e, 0.8 + e, e, e};
outer[] = CombinedBoundary{ Surface{:}; };
outer[] = Abs(outer[]);
outer[] -= {feet[]};
Physical Curve("feet") = {feet[]};
Physical Curve("free") = {outer[]};
Mesh.MeshSizeMax = h;
