// NAFEMS T3 "One-dimensional transient heat transfer" (TNSB Rev. 3, 1990).
// A bar of length 0.1 m modelled as a thin 2-D strip (width w, any value: the
// problem is 1-D because the long edges are insulated).  SI units (m).
//
//   y  P4 ----------------- P5 ------ P6
//   |  |                    |         |       x = 0   : T = 0            ("cold_end", point A)
//   |  |       bar          |   bar   |       x = 0.1 : T = 100 sin(pi t/40) ("hot_end", point B)
//   |  P1 ----------------- P2 ------ P3 -> x  y = 0, w : insulated       ("insulated")
//   A (x=0)            x = 0.08          B (x=0.1)
//
// Target: T at x = 0.08 m, t = 32 s = 36.60 C (initial T = 0 everywhere).
// The strip is split at x = 0.08 so that a mesh node lies exactly on the target.
// Structured (transfinite) mesh; "h" is the element length along the bar.

If (!Exists(Lb)) Lb = 0.1;   EndIf   // bar length
If (!Exists(xt)) xt = 0.08;  EndIf   // target abscissa
If (!Exists(w))  w  = 0.01;  EndIf   // strip width (bar is 0.01 x 0.01 m in most reproductions)
If (!Exists(h))  h  = 0.01;  EndIf   // element length along the bar
If (!Exists(ny)) ny = 1;     EndIf   // element layers across the width

Point(1) = {0,  0, 0};
Point(2) = {xt, 0, 0};   // target
Point(3) = {Lb, 0, 0};
Point(4) = {0,  w, 0};
Point(5) = {xt, w, 0};
Point(6) = {Lb, w, 0};

Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 6};        // hot end
Line(4) = {6, 5};
Line(5) = {5, 4};
Line(6) = {4, 1};        // cold end
Line(7) = {2, 5};        // internal line at x = 0.08

Curve Loop(1) = {1, 7, 5, 6};
Plane Surface(1) = {1};
Curve Loop(2) = {2, 3, 4, -7};
Plane Surface(2) = {2};

n1 = Ceil(xt / h - 1e-9);
n2 = Ceil((Lb - xt) / h - 1e-9);
Transfinite Curve {1, 5} = n1 + 1;
Transfinite Curve {2, 4} = n2 + 1;
Transfinite Curve {3, 6, 7} = ny + 1;
Transfinite Surface {1};
Transfinite Surface {2};

Physical Surface("bar") = {1, 2};
Physical Curve("cold_end") = {6};
Physical Curve("hot_end") = {3};
Physical Curve("insulated") = {1, 2, 4, 5};
Physical Point("target") = {2};
