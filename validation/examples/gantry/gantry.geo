// A portal (gantry) milling machine as a coarse 3-D assembly, SI units (m): a bed, two
// columns, a cross beam on them and a spindle head hanging from the beam's front at mid-span.
// The spindle's losses heat the head; δ: the tool (a corner of the head's lowest face) and the
// workpiece block on the bed under it approaching along z. The probes are corners of the boxes:
// vertices of the geometry, so nodes of any mesh (`export ccx` compares displacements at nodes).
//
//            +=========== beam ===========+      z
//            |  |       [head]         |  |      |
//            |c1|         |T           |c2|      +-- x   (y: depth, the beam's front at y = 0)
//            |  |         w            |  |
//        +---+--+----------------------+--+---+
//        |                bed                 |
//        +------------------------------------+
//
// Named groups: regions bed, column_left, column_right, beam, head, work; boundaries feet, free.
SetFactory("OpenCASCADE");
If (!Exists(size)) size = 0.2; EndIf
If (!Exists(beam_height)) beam_height = 0.35; EndIf      // cross-beam depth (z), m
L = 2.4; D = 0.8; hb = 0.3; hc = 1.2;                    // bed length, depth, height; column height
zb = hb + hc;                                            // underside of the beam

Box(1) = {0, 0, 0, L, D, hb};                            // bed
Box(2) = {0, 0.2, hb, 0.35, 0.4, hc};                    // left column
Box(3) = {L - 0.35, 0.2, hb, 0.35, 0.4, hc};             // right column
Box(4) = {0, 0.2, zb, L, 0.4, beam_height};              // cross beam
Box(5) = {L / 2 - 0.15, -0.1, zb - 0.55, 0.3, 0.3, 0.55 + beam_height};  // head on the beam's front
Box(6) = {L / 2 - 0.15, 0.0, hb, 0.3, 0.2, 0.1};         // workpiece block on the bed, under the head
BooleanFragments{ Volume{1:6}; Delete; }{}

e = 1e-6;
hd[] = Volume In BoundingBox{L / 2 - 0.15 - e, -0.1 - e, zb - 0.55 - e, L / 2 + 0.15 + e, 0.2 + e, zb + beam_height + e};
bm[] = Volume In BoundingBox{-e, 0.2 - e, zb - e, L + e, 0.6 + e, zb + beam_height + e};
bm[] -= {hd[]};
Physical Volume("bed") = Volume In BoundingBox{-e, -e, -e, L + e, D + e, hb + e};
Physical Volume("column_left") = Volume In BoundingBox{-e, 0.2 - e, hb - e, 0.35 + e, 0.6 + e, zb + e};
Physical Volume("column_right") = Volume In BoundingBox{L - 0.35 - e, 0.2 - e, hb - e, L + e, 0.6 + e, zb + e};
Physical Volume("beam") = {bm[]};
Physical Volume("head") = {hd[]};
Physical Volume("work") = Volume In BoundingBox{L / 2 - 0.15 - e, -e, hb - e, L / 2 + 0.15 + e, 0.2 + e, hb + 0.1 + e};
feet[] = Surface In BoundingBox{-e, -e, -e, L + e, D + e, e};
outer[] = Abs(CombinedBoundary{ Volume{:}; });
outer[] -= {feet[]};
Physical Surface("feet") = {feet[]};
Physical Surface("free") = {outer[]};
// the probe points are given by coordinates in the case (points inside a volume are not meshed)
Mesh.MeshSizeMax = size;
