// NAFEMS T4 "Two-dimensional heat transfer with convection" (TNSB Rev. 3, 1990).
// Steady conduction in a 0.6 m x 1.0 m plate.  SI units (m).
//
//   y
//   D (0,1) ------------------ C (0.6,1)     AB : T = 100 C                  ("hot_edge")
//   |                          |             BC, CD : -k dT/dn = h (T - 0 C),  ("convection")
//   |                          |                      h = 750 W/m2K
//   |         plate            |             DA : insulated, q = 0         ("insulated")
//   |                          E (0.6,0.2)   k = 52 W/mK, no heat source
//   |                          |
//   A (0,0) ------------------ B (0.6,0) --> x
//
// Target: T at E = (0.6, 0.2) = 18.25 C (18.3 C in some reproductions).

If (!Exists(W))  W  = 0.6; EndIf
If (!Exists(H))  H  = 1.0; EndIf
If (!Exists(yE)) yE = 0.2; EndIf
If (!Exists(h))  h  = 0.05; EndIf    // element size far from E
If (!Exists(hE)) hE = h / 4; EndIf   // element size at E and along AB/BC near B

Point(1) = {0, 0, 0, h};    // A
Point(2) = {W, 0, 0, hE};   // B  (temperature jumps from 100 C to convective edge here)
Point(3) = {W, yE, 0, hE};  // E  target
Point(4) = {W, H, 0, h};    // C
Point(5) = {0, H, 0, h};    // D

Line(1) = {1, 2};   // AB
Line(2) = {2, 3};   // BE
Line(3) = {3, 4};   // EC
Line(4) = {4, 5};   // CD
Line(5) = {5, 1};   // DA

Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};

Physical Surface("plate") = {1};
Physical Curve("hot_edge") = {1};
Physical Curve("convection") = {2, 3, 4};
Physical Curve("insulated") = {5};
Physical Point("target") = {3};
