// Two blocks touching along x = L (a composite wall): "left" [0, L] x [0, H] and "right"
// [L, 2L] x [0, H], made conformal by BooleanFragments; their interface is the curve
// "left/right". Sizes can be set before parsing (h, L, H).
SetFactory("OpenCASCADE");
If (!Exists(L)) L = 0.1; EndIf
If (!Exists(H)) H = 0.05; EndIf
If (!Exists(h)) h = 0.01; EndIf
Rectangle(1) = {0, 0, 0, L, H};
Rectangle(2) = {L, 0, 0, L, H};
BooleanFragments{ Surface{1}; Delete; }{ Surface{2}; Delete; }
e = 1e-6;
sl[] = Surface In BoundingBox {-e, -e, -e, L + e, H + e, e};
sr[] = Surface In BoundingBox {L - e, -e, -e, 2 * L + e, H + e, e};
ci[] = Curve In BoundingBox {L - e, -e, -e, L + e, H + e, e};
ch[] = Curve In BoundingBox {-e, -e, -e, e, H + e, e};
cc[] = Curve In BoundingBox {2 * L - e, -e, -e, 2 * L + e, H + e, e};
cb[] = Curve In BoundingBox {-e, -e, -e, 2 * L + e, e, e};
ct[] = Curve In BoundingBox {-e, H - e, -e, 2 * L + e, H + e, e};
pm[] = Point In BoundingBox {L - e, -e, -e, L + e, e, e};
Physical Surface("left") = {sl[]};
Physical Surface("right") = {sr[]};
Physical Curve("left/right") = {ci[]};
Physical Curve("hot") = {ch[]};
Physical Curve("cold") = {cc[]};
Physical Curve("bottom") = {cb[]};
Physical Curve("top") = {ct[]};
Physical Point("mid") = {pm[]};
Mesh.MeshSizeMax = h;
