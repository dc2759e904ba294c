(a second duty, for checking the reduced model: short strokes near the fixed bearing, then long ones)
G21 G90
G0 X100
G1 X350 F9000
G1 X100 F9000
G1 X350 F9000
G1 X100 F9000
G4 X15
G1 X750 F4000
G4 X40
G1 X50 F8000
G4 X10
M30
