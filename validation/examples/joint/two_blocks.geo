SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 0.1, 0.05};
Rectangle(2) = {0.1, 0, 0, 0.1, 0.05};
BooleanFragments{ Surface{1}; Delete; }{ Surface{2}; Delete; }
e = 1e-6;
Physical Surface("left") = {Surface In BoundingBox {-e, -e, -e, 0.1 + e, 0.05 + e, e}};
Physical Surface("right") = {Surface In BoundingBox {0.1 - e, -e, -e, 0.2 + e, 0.05 + e, e}};
Physical Curve("left/right") = {Curve In BoundingBox {0.1 - e, -e, -e, 0.1 + e, 0.05 + e, e}};
Physical Curve("hot") = {Curve In BoundingBox {-e, -e, -e, e, 0.05 + e, e}};
Physical Curve("cold") = {Curve In BoundingBox {0.2 - e, -e, -e, 0.2 + e, 0.05 + e, e}};
Mesh.MeshSizeMax = 0.01;
