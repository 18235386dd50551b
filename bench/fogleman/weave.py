# fogleman/sdf's weave.py in sdfc's Python (bench/fogleman/README.md); z is up, as there.
from sdfc import *

Z = (0, 0, 1)
f = round_box((1.6, 0.5, 0.125), 0.1).translate(1.5, 0, 0.0625)
# Bent up by 0.1875 from x = 0.75 to 2.25, eased in and out quadratically; cut to its box,
# which the formula does not state.
f = field("""let t = clamp((p.x - 0.75) / 1.5, 0, 1);
  let e = 2 * min(t, 0.5) * min(t, 0.5) + 0.5 - 2 * (1 - max(t, 0.5)) * (1 - max(t, 0.5));
  distance(f, p + vec3(0, 0, 0.1875 * e))""", f=f) & box((1.7, 0.6, 0.4)).translate(1.5, 0, 0.1)
f = f.repeat_polar(3, Z)

f = f.repeat((2.7, 5.4, 0))
f |= f.translate(2.7 / 2, 2.7, 0)

f &= infinite_cylinder(10, Z)
f |= smooth_intersect(0.25, infinite_cylinder(12, Z) - infinite_cylinder(10, Z), slab(1, Z))

if __name__ == "__main__":
    f.save("weave.stl", bounds=((-12.2, -12.2, -0.6), (12.2, 12.2, 0.6)))
