# fogleman/sdf's knurling.py in sdfc's Python (bench/fogleman/README.md): built along y,
# sdfc's up, and turned to z at the end.
from sdfc import *

# main body
f = rounded_cylinder(1, 0.1, 5)

# knurling
x = box((0.5, 2, 0.5)).rotate_y(deg(45)).translate(1.6, 0, 0).repeat_polar(24)
x = x.twist(0.75) | x.twist(-0.75)
f = smooth_subtract(0.1, f, x)

# central hole
f = smooth_subtract(0.1, f, infinite_cylinder(0.5))

# vent holes
c = infinite_cylinder(0.25, (1, 0, 0))
f = smooth_subtract(0.1, f, c.translate(0, -2.5, 0))
f = smooth_subtract(0.1, f, c.translate(0, 2.5, 0)).rotate_x(deg(90))

if __name__ == "__main__":
    f.save("knurling.stl")
