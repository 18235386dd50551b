//% The interval functions of analytic ray tracing, one section per `//= NAME` line; the
//% generator (analytic.rs) emits only the sections a scene's primitives use.

//= sphere
// Roots of |o + t·d|² = r².
fn sphere_interval(o: vec3<f32>, d: vec3<f32>, r2: f32) -> Interval {
    let a = dot(d, d);
    let b = dot(o, d);
    let c = dot(o, o) - r2;
    let disc = b * b - a * c;
    if !(disc >= 0.0) {
        return missed();
    }
    let q = sqrt(disc);
    let near = (-b - q) / a;
    let far = (-b + q) / a;
    return Interval(near, far, o + d * near, o + d * far);
}

//= slab
// The slab |x| <= h: (entry, exit); a ray parallel to it is inside for every t or none.
fn slab(o: f32, d: f32, h: f32) -> vec2<f32> {
    if d == 0.0 {
        return select(vec2<f32>(BIG, -BIG), vec2<f32>(-BIG, BIG), abs(o) <= h);
    }
    let inv = 1.0 / d;
    let t1 = (-h - o) * inv;
    let t2 = (h - o) * inv;
    return vec2<f32>(min(t1, t2), max(t1, t2));
}

//= clip
// Narrows s to one slab along the unit axis e: entering it last or leaving it first sets
// that end's normal to the slab's face.
fn clip(s: Interval, t: vec2<f32>, e: vec3<f32>, d: f32) -> Interval {
    var r = s;
    let face = e * select(1.0, -1.0, d < 0.0);
    if t.x > r.near {
        r.near = t.x;
        r.n_near = -face;
    }
    if t.y < r.far {
        r.far = t.y;
        r.n_far = face;
    }
    return r;
}

//= box
// The box |x| <= half: the intersection of three slabs.
fn box_interval(o: vec3<f32>, d: vec3<f32>, half: vec3<f32>) -> Interval {
    var s = Interval(-BIG, BIG, vec3<f32>(0.0), vec3<f32>(0.0));
    s = clip(s, slab(o.x, d.x, half.x), vec3<f32>(1.0, 0.0, 0.0), d.x);
    s = clip(s, slab(o.y, d.y, half.y), vec3<f32>(0.0, 1.0, 0.0), d.y);
    s = clip(s, slab(o.z, d.z, half.z), vec3<f32>(0.0, 0.0, 1.0), d.z);
    return s;
}

//= cylinder
// The capped cylinder x² + z² <= r², |y| <= h.
fn cylinder_interval(o: vec3<f32>, d: vec3<f32>, r2: f32, h: f32) -> Interval {
    let a = d.x * d.x + d.z * d.z;
    let b = o.x * d.x + o.z * d.z;
    let c = o.x * o.x + o.z * o.z - r2;
    var s = Interval(-BIG, BIG, vec3<f32>(0.0), vec3<f32>(0.0));
    if a == 0.0 {
        if c > 0.0 {
            return missed();
        }
    } else {
        let disc = b * b - a * c;
        if !(disc >= 0.0) {
            return missed();
        }
        let q = sqrt(disc);
        s.near = (-b - q) / a;
        s.far = (-b + q) / a;
        let pn = o + d * s.near;
        let pf = o + d * s.far;
        s.n_near = vec3<f32>(pn.x, 0.0, pn.z);
        s.n_far = vec3<f32>(pf.x, 0.0, pf.z);
    }
    return clip(s, slab(o.y, d.y, h), vec3<f32>(0.0, 1.0, 0.0), d.y);
}

//= capsule
// The capsule: the convex hull of two spheres at y = ±h, which is the union of them and the
// capped cylinder between them, so the ray's interval is the hull of the three intervals. The
// normals point away from the nearest point of the segment.
fn capsule_interval(o: vec3<f32>, d: vec3<f32>, r2: f32, h: f32) -> Interval {
    let up = vec3<f32>(0.0, h, 0.0);
    let a = sphere_interval(o - up, d, r2);
    let b = sphere_interval(o + up, d, r2);
    let c = cylinder_interval(o, d, r2, h);
    var near = BIG;
    var far = -BIG;
    if a.near <= a.far {
        near = min(near, a.near);
        far = max(far, a.far);
    }
    if b.near <= b.far {
        near = min(near, b.near);
        far = max(far, b.far);
    }
    if c.near <= c.far {
        near = min(near, c.near);
        far = max(far, c.far);
    }
    if !(near <= far) {
        return missed();
    }
    let pn = o + d * near;
    let pf = o + d * far;
    let nn = vec3<f32>(pn.x, pn.y - clamp(pn.y, -h, h), pn.z);
    let nf = vec3<f32>(pf.x, pf.y - clamp(pf.y, -h, h), pf.z);
    return Interval(near, far, nn, nf);
}

//= plane
// The half-space dot(p, n) <= h.
fn plane_interval(o: vec3<f32>, d: vec3<f32>, n: vec3<f32>, h: f32) -> Interval {
    let dn = dot(n, d);
    let above = dot(n, o) - h;
    if dn == 0.0 {
        if above <= 0.0 {
            return Interval(-BIG, BIG, n, n);
        }
        return missed();
    }
    let t = -above / dn;
    if dn > 0.0 {
        return Interval(-BIG, t, n, n);
    }
    return Interval(t, BIG, n, n);
}

//= enters
// Whether a ray (from the group's centre) meets a group's box of half-extents h between 0
// and limit: groups of the bounding-volume hierarchy are skipped when it does not.
fn enters(o: vec3<f32>, d: vec3<f32>, h: vec3<f32>, limit: f32) -> bool {
    let s = box_interval(o, d, h);
    return s.near <= s.far && s.far > 0.0 && s.near < limit;
}

//= into
// A vector in a primitive's frame, given the rows of its world-to-local matrix.
fn into(v: vec3<f32>, r0: vec3<f32>, r1: vec3<f32>, r2: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(r0, v), dot(r1, v), dot(r2, v));
}

//= to_world
// An interval's normals in world space: normals map by the transpose of the world-to-local
// matrix.
fn to_world(s: Interval, r0: vec3<f32>, r1: vec3<f32>, r2: vec3<f32>) -> Interval {
    let a = r0 * s.n_near.x + r1 * s.n_near.y + r2 * s.n_near.z;
    let b = r0 * s.n_far.x + r1 * s.n_far.y + r2 * s.n_far.z;
    return Interval(s.near, s.far, a, b);
}
