// A column on a bed, conformal (BooleanFragments), for the CalculiX export tests: small and coarse.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.3, 0.2, 0.06};
Box(2) = {0.1, 0.05, 0.06, 0.1, 0.1, 0.2};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
e = 1e-6;
Physical Volume("bed") = {Volume In BoundingBox {-e, -e, -e, 0.3 + e, 0.2 + e, 0.06 + e}};
Physical Volume("column") = {Volume In BoundingBox {0.1 - e, 0.05 - e, 0.06 - e, 0.2 + e, 0.15 + e, 0.26 + e}};
Physical Surface("bed/column") = {Surface In BoundingBox {0.1 - e, 0.05 - e, 0.06 - e, 0.2 + e, 0.15 + e, 0.06 + e}};
Physical Surface("floor") = {Surface In BoundingBox {-e, -e, -e, 0.3 + e, 0.2 + e, e}};
Physical Surface("head") = {Surface In BoundingBox {0.1 - e, 0.05 - e, 0.26 - e, 0.2 + e, 0.15 + e, 0.26 + e}};
Physical Surface("side") = {Surface In BoundingBox {0.2 - e, 0.05 - e, 0.06 - e, 0.2 + e, 0.15 + e, 0.26 + e}};
Physical Point("tip") = {Point In BoundingBox {0.2 - e, 0.15 - e, 0.26 - e, 0.2 + e, 0.15 + e, 0.26 + e}};
Mesh.MeshSizeMax = 0.05;
