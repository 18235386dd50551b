# fogleman/sdf's gearlike.py in sdfc's Python (bench/fogleman/README.md); z is up, as there.
from sdfc import *

Z = (0, 0, 1)
f = smooth_intersect(0.1, sphere(2), slab(1, Z))
f = smooth_subtract(0.1, f, infinite_cylinder(1, Z))
f = smooth_subtract(0.1, f, infinite_cylinder(0.25, Z).translate(2, 0, 0).repeat_polar(16, Z))

if __name__ == "__main__":
    f.save("gearlike.stl")
