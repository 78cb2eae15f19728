; Tuning run from config.g with M98: lower jerk on X and Y after ringing tests
M566 X600 Y600                                 ; mm/min
M205 X5                                        ; printing moves only (mm/s); the M566 limit stays
