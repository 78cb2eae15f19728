; A single 90-degree corner as G-code: two 20 mm legs from the origin, printing at
; 100 mm/s. scenarios/gcode_corner.toml runs it with settle's planner;
; scenarios/gcode_corner_reference.toml is the same corner as a [corner] run.
G21
G90
M83
;LAYER:0
G1 X20 Y0 E0.8 F6000
G1 X20 Y20 E0.8
