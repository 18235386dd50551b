# fogleman/sdf's README example in sdfc's Python (bench/fogleman/README.md): a sphere cut to
# a box, less three cylinders along the axes.
from sdfc import *

f = sphere(1) & box(0.75)  # box takes half-extents

c = [infinite_cylinder(0.5, axis) for axis in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
f -= union(c)

if __name__ == "__main__":
    f.save("out.stl")
