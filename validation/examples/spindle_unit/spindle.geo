// A motor-spindle unit, axisymmetric (x = r, y = z along the spindle axis), metres:
// a shaft (bore 65 mm), a front and a rear bearing (outer diameter 100 mm, dm = 82.5 mm), a
// housing with a cooling jacket on its outer face, mounted by its rear face.
SetFactory("OpenCASCADE");
size = 0.004;
Rectangle(1) = {0, 0, 0, 0.0325, 0.40};          // shaft
Rectangle(2) = {0.05, 0.05, 0, 0.04, 0.30};      // housing
Rectangle(3) = {0.0325, 0.30, 0, 0.0175, 0.03};  // front bearing
Rectangle(4) = {0.0325, 0.07, 0, 0.0175, 0.03};  // rear bearing
BooleanFragments{ Surface{1, 2, 3, 4}; Delete; }{}
e = 1e-6;
Physical Surface("shaft") = Surface In BoundingBox{-e, -e, -e, 0.0325 + e, 0.40 + e, e};
Physical Surface("housing") = Surface In BoundingBox{0.05 - e, 0.05 - e, -e, 0.09 + e, 0.35 + e, e};
Physical Surface("front_bearing") = Surface In BoundingBox{0.0325 - e, 0.30 - e, -e, 0.05 + e, 0.33 + e, e};
Physical Surface("rear_bearing") = Surface In BoundingBox{0.0325 - e, 0.07 - e, -e, 0.05 + e, 0.10 + e, e};
Physical Curve("jacket") = Curve In BoundingBox{0.09 - e, 0.05 - e, -e, 0.09 + e, 0.35 + e, e};
Physical Curve("nose") = Curve In BoundingBox{0.0325 - e, 0.33 - e, -e, 0.0325 + e, 0.40 + e, e};
Physical Curve("mount") = Curve In BoundingBox{0.05 - e, 0.05 - e, -e, 0.09 + e, 0.05 + e, e};
Physical Point("tool") = Point In BoundingBox{-e, 0.40 - e, -e, e, 0.40 + e, e};
Mesh.MeshSizeMax = size;
