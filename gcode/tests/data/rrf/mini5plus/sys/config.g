; Configuration file for Duet 3 Mini 5+ (firmware version 3.5), a Cartesian printer
; executed by the firmware on start-up
; Test configuration of settle-gcode: what RepRapFirmware would use after reading it is
; asserted in gcode/tests/gcode/config_rrf.rs.

; General preferences
G90                                            ; send absolute coordinates...
M83                                            ; ...but relative extruder moves
M550 P"Mini5 Cartesian"                        ; set printer name

; Wait a moment for the CAN expansion boards to become available
G4 S2

; Network
M552 S1                                        ; enable network
M586 P0 S1                                     ; enable HTTP
M586 P1 S0                                     ; disable FTP
M586 P2 S0                                     ; disable Telnet

; Drives
M569 P0.0 S1 D2                                ; physical drive 0.0 goes forwards (X), spreadCycle
M569 P0.1 S0 D2                                ; physical drive 0.1 goes backwards (Y)
M569 P0.2 S1 D2                                ; physical drive 0.2 goes forwards (Z)
M569 P0.3 S1 D3                                ; physical drive 0.3 goes forwards (E0), stealthChop
M584 X0.0 Y0.1 Z0.2 E0.3                       ; set drive mapping
M350 X16 Y16 Z16 E16 I1                        ; configure microstepping with interpolation
M92 X80.00 Y80.00 Z400.00 E420.00              ; set steps per mm (at x16)
M566 X900.00 Y900.00 Z60.00 E120.00            ; set maximum instantaneous speed changes (mm/min)
M203 X18000.00 Y18000.00 Z600.00 E3600.00      ; set maximum speeds (mm/min)
M201 X3000.00 Y3000.00 Z100.00 E250.00         ; set accelerations (mm/s^2)
M906 X1200 Y1200 Z800 E800 I30                 ; set motor currents (mA) and motor idle factor in per cent
M84 S30                                        ; set idle timeout

; Axis Limits
M208 X0 Y0 Z0 S1                               ; set axis minima
M208 X235 Y235 Z250 S0                         ; set axis maxima

; Kinematics
M669 K0                                        ; Cartesian

; Endstops
M574 X1 S1 P"io1.in"                           ; configure switch-type (e.g. microswitch) endstop for low end on X via pin io1.in
M574 Y1 S1 P"io2.in"                           ; configure switch-type (e.g. microswitch) endstop for low end on Y via pin io2.in

; Z-Probe
M558 P8 C"^io3.in" H5 F120 T6000               ; set Z probe type to switch and the dive height + speeds
G31 P500 X-25 Y0 Z2.5                          ; set Z probe trigger value, offset and trigger height
M557 X15:215 Y15:195 S20                       ; define mesh grid

; Heaters
M308 S0 P"temp0" Y"thermistor" T100000 B4138   ; configure sensor 0 as thermistor on pin temp0
M950 H0 C"out0" T0                             ; create bed heater output on out0 and map it to sensor 0
M307 H0 B1 S1.00                               ; enable bang-bang mode for the bed heater and set PWM limit
M140 H0                                        ; map heated bed to heater 0
M143 H0 S120                                   ; set temperature limit for heater 0 to 120C
M308 S1 P"temp1" Y"thermistor" T100000 B4138 C7.06e-8 ; configure sensor 1 as thermistor on pin temp1
M950 H1 C"out1" T1                             ; create nozzle heater output on out1 and map it to sensor 1
M143 H1 S280                                   ; set temperature limit for heater 1 to 280C

; Fans
M950 F0 C"out3" Q500                           ; create fan 0 on pin out3 and set its frequency
M106 P0 S0 H-1                                 ; set fan 0 value. Thermostatic control is turned off

; Tools
M563 P0 D0 H1 F0                               ; define tool 0
G10 P0 X0 Y0 Z0                                ; set tool 0 axis offsets
G10 P0 R0 S0                                   ; set initial tool 0 active and standby temperatures to 0C

; Motion tuning (added after the configuration tool's output)
M350 X32 Y32 I1                                ; finer microstepping on X and Y: the firmware keeps 1 mm = 1 mm (160 steps/mm)
M92 Z1600 S64                                  ; Z steps per mm given at x64: 400 at the x16 in force
M204 P2000 T4000                               ; print and travel accelerations
M593 P"mzv" F42.5 S0.1                         ; input shaping, from the accelerometer plugin

; Toolboard variant (not present on this machine)
if boards[1] != null && boards[1].shortName == "TOOL1LC"
    M92 E690                                   ; toolboard extruder
    M906 X1500 Y1500                           ; would raise the currents
global maxPrintAccel = 3000

M98 P"tuning.g"                                ; machine-specific tuning in /sys
M98 P"0:/macros/z_limits.g"                    ; a macro from the card's /macros folder
M98 P"absent.g"                                ; not on this card
M501                                           ; load saved parameters (config-override.g)
