; Called from config.g as M98 P"0:/macros/z_limits.g"
M208 Z-0.5:245                                 ; Z travel with the new bed
