# fogleman/sdf's blobby.py in sdfc's Python (bench/fogleman/README.md).
from sdfc import *


def s(axis):
    a, b = [3 * x for x in axis], [-3 * x for x in axis]
    return smooth_union(1, sphere(0.75).translate(b) | sphere(0.75).translate(a), segment(b, a, 0.5))


f = smooth_union(1, [sphere(1.5), s((1, 0, 0)), s((0, 1, 0)), s((0, 0, 1))])

if __name__ == "__main__":
    f.save("blobby.stl")
