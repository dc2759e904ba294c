// A feed axis, a 2-D section (x along the axis, y up), metres: a bed with a guide rail, the
// fixed bearing's block holding a ball screw (40 mm, lead 10 mm) whose far end runs in a
// floating bearing (radial only: not joined to the bed here). The nut and the carriage move
// with the table: x_m of the NC program plus 0.2 m.
SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 1.2, 0.08};            // bed
Rectangle(2) = {0.02, 0.08, 0, 0.06, 0.08};     // fixed bearing block
Rectangle(3) = {0.08, 0.11, 0, 1.02, 0.02};     // screw
Rectangle(4) = {1.10, 0.11, 0, 0.02, 0.02};     // floating bearing
Rectangle(5) = {0.15, 0.08, 0, 0.90, 0.02};     // guide rail
BooleanFragments{ Surface{1, 2, 3, 4, 5}; Delete; }{}
e = 1e-6;
Physical Surface("bed") = Surface In BoundingBox{-e, -e, -e, 1.2 + e, 0.08 + e, e};
Physical Surface("bearing_fixed") = Surface In BoundingBox{0.02 - e, 0.08 - e, -e, 0.08 + e, 0.16 + e, e};
Physical Surface("screw") = Surface In BoundingBox{0.08 - e, 0.11 - e, -e, 1.10 + e, 0.13 + e, e};
Physical Surface("bearing_float") = Surface In BoundingBox{1.10 - e, 0.11 - e, -e, 1.12 + e, 0.13 + e, e};
Physical Surface("rail") = Surface In BoundingBox{0.15 - e, 0.08 - e, -e, 1.05 + e, 0.10 + e, e};
Physical Curve("base") = Curve In BoundingBox{-e, -e, -e, 1.2 + e, e, e};
Physical Point("screw_end") = Point In BoundingBox{1.12 - e, 0.11 - e, -e, 1.12 + e, 0.11 + e, e};
Mesh.MeshSizeMax = 0.01;
