; config-override.g file generated in response to M500 at 2024-05-02 14:11
; This is a system-generated file - do not edit
; Heater model parameters
M307 H0 R0.343 K0.292:0.000 D6.74 E1.35 S1.00 B0
M307 H1 R2.513 K0.337:0.000 D5.91 E1.35 S1.00 B0 V23.8
; Workplace coordinates
G10 L2 P1 X0.00 Y0.00 Z0.00
