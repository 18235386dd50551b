//! The physically based material's light at a hit (docs/rendering.md, "Physically based
//! materials"), with the formulas of `sdfc_compiler::pbr`, and the weights of what a hit seen
//! from outside adds and spawns: its local colour, its reflected and its refracted ray (with
//! Schlick's Fresnel term where the material has it).

use super::context::{Mat, PbrMat, Sky};
use super::vec::V3;
use sdfc_compiler::{pbr, Float};

/// The weights of a hit's local colour, reflected ray and refracted ray.
#[derive(Debug, Clone, Copy)]
pub(super) struct Lobes<T> {
    pub local: T,
    pub reflect: V3<T>,
    pub transmit: V3<T>,
}

/// What a `pbr` material's terms share at a hit of base colour `c` seen from `v`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Surface<T> {
    pub pbr: PbrMat<T>,
    pub c: V3<T>,
    /// `max(N·V, NV_MIN)`.
    pub nv: T,
    /// The reflectance at normal incidence: the dielectric's `F0`, or the base colour for
    /// a metal (mixed by `metallic`).
    pub f0: V3<T>,
    /// The specular lobe's directional albedo `E_s = clamp(F0·A + B, 0, 1)` (the split-sum
    /// fit at `N·V`).
    pub albedo: V3<T>,
    /// The diffuse weight `k_d = 1 − metallic − transparency` (the dielectric part that is
    /// not transmitted).
    pub kd: T,
}

/// The terms a `pbr` material `m` shares at a hit of normal `n`, base colour `c`, seen
/// from `v` (towards the viewer).
pub(super) fn surface<T: Float>(
    m: &Mat<T>,
    p: PbrMat<T>,
    c: V3<T>,
    n: V3<T>,
    v: V3<T>,
) -> Surface<T> {
    let nv = n.dot(v).max(T::from_f64(pbr::NV_MIN));
    let f0 = V3::splat(m.f0 * (T::one() - p.metallic)) + c * p.metallic;
    let (a, b) = pbr::environment(nv, p.roughness);
    let e = |f: T| (f * a + b).clamp(T::zero(), T::one());
    Surface {
        pbr: p,
        c,
        nv,
        f0,
        albedo: V3::new(e(f0.x), e(f0.y), e(f0.z)),
        kd: (T::one() - p.metallic - m.transparency).max(T::zero()),
    }
}

/// The light a `pbr` surface sends towards the viewer from a lamp of colour `il` in
/// direction `l` (towards it), before attenuation and shadow, where `N·L > 0`:
/// `(k_d·(1 − F)·C + π·D·Vis·F)·I_l·(N·L)` with `H = normalize(L + V)`,
/// `F = F0 + (1 − F0)·(1 − V·H)⁵`, `D` GGX and `Vis` the height-correlated Smith term.
pub(super) fn lamp<T: Float>(s: &Surface<T>, n: V3<T>, v: V3<T>, l: V3<T>, il: V3<T>) -> V3<T> {
    let nl = n.dot(l);
    let h = (l + v).normalize();
    let nh = n.dot(h).max(T::zero());
    let f = pbr::schlick(v.dot(h));
    let fresnel = s.f0 + (V3::splat(T::one()) - s.f0) * f;
    let a = s.pbr.alpha;
    let spec = T::from_f64(std::f64::consts::PI) * pbr::ggx(nh, a) * pbr::visibility(s.nv, nl, a);
    let diffuse = (V3::splat(T::one()) - fresnel).mul_v(s.c) * s.kd;
    (diffuse + fresnel * spec).mul_v(il) * nl
}

/// The light a `pbr` surface sends towards the viewer from a sky, before occlusion: the
/// diffuse part `k_d·(1 − E_s)·C·E(N)/π` and the specular part the reflected ray does not
/// carry, `E_s·(1 − g)·E(R)/π`, the sky's irradiance about the mirror direction `R` standing
/// for its radiance blurred by the lobe.
pub(super) fn sky<T: Float>(s: &Surface<T>, sky: &Sky<T>, n: V3<T>, v: V3<T>) -> V3<T> {
    let r = n * (T::from_f64(2.0) * n.dot(v)) - v;
    let one = V3::splat(T::one());
    let diffuse = (one - s.albedo).mul_v(s.c).mul_v(sky.irradiance_at(n.y)) * s.kd;
    let spec = s.albedo.mul_v(sky.irradiance_at(r.y)) * (T::one() - s.pbr.mirror);
    diffuse + spec
}

/// The weight of the local colour of a hit on `m` of normal `n` seen along `dir` (that of
/// [`lobes`], without the base colour it does not need).
pub(super) fn local_weight<T: Float>(m: &Mat<T>, n: V3<T>, dir: V3<T>) -> T {
    if m.pbr.is_some() {
        T::one()
    } else {
        lobes(m, n, dir, V3::zero).local
    }
}

/// The weights of a hit on `m` of normal `n` seen along `dir`: Phong's `1 − r − τ`, `r` and
/// `τ` (with `fresnel`, `pbr::fresnel_weights` at `|N·V|`); a `pbr` material's local colour
/// has weight 1 (its terms weigh themselves), its reflected ray `E_s·g`, its refracted ray
/// `τ·(1 − E_s)·C`. `colour` gives the base colour, asked for only for a `pbr` material
/// (whose `F0` and refracted ray it tints).
pub(super) fn lobes<T: Float>(
    m: &Mat<T>,
    n: V3<T>,
    dir: V3<T>,
    colour: impl FnOnce() -> V3<T>,
) -> Lobes<T> {
    if let Some(p) = m.pbr {
        let c = colour();
        let s = surface(m, p, c, n, -dir);
        return Lobes {
            local: T::one(),
            reflect: s.albedo * p.mirror,
            transmit: (V3::splat(T::one()) - s.albedo).mul_v(c) * m.transparency,
        };
    }
    let (local, reflect, transmit) = if m.fresnel {
        pbr::fresnel_weights(m.reflect, m.transparency, m.f0, n.dot(dir).abs())
    } else {
        (
            T::one() - m.reflect - m.transparency,
            m.reflect,
            m.transparency,
        )
    };
    Lobes {
        local,
        reflect: V3::splat(reflect),
        transmit: V3::splat(transmit),
    }
}
