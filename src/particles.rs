//! The particle store (SPEC §4): struct-of-arrays, one owner for every
//! per-particle field.
//!
//! Every field is indexed by particle number `i` in `0..len()`. Anything that
//! adds, splits or permutes particles goes through the methods here so that
//! no column is forgotten.

use crate::math::{Real, Vec2};

/// Bit flags describing a particle's role.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct ParticleFlags(pub u8);

impl ParticleFlags {
    /// On the outer boundary of its body.
    pub const SURFACE: u8 = 1;
    /// x (radial) component of the generalized displacement held at zero
    /// (clamp, roller, symmetry plane, or the axis in axisymmetry).
    pub const FIX_X: u8 = 2;
    /// y component held at zero.
    pub const FIX_Y: u8 = 4;
    /// On a crack face.
    pub const CRACK_FACE: u8 = 8;
    /// In the contact slave set.
    pub const SLAVE: u8 = 16;
    /// On the symmetry axis (axisymmetry).
    pub const ON_AXIS: u8 = 32;
    /// Detached from its body: erosion left it (almost) no material of its
    /// own, and no shape function holds it any more; it flies free with
    /// its mass (`crate::fracture::CrackGrowth::detach_isolated`).
    pub const DETACHED: u8 = 64;

    #[inline]
    pub fn has(self, f: u8) -> bool {
        self.0 & f != 0
    }
    #[inline]
    pub fn set(&mut self, f: u8) {
        self.0 |= f;
    }
    /// Zero the components of `v` that these flags hold fixed.
    #[inline]
    pub fn constrain(self, v: &mut Vec2) {
        if self.has(Self::FIX_X) {
            v.x = 0.0;
        }
        if self.has(Self::FIX_Y) {
            v.y = 0.0;
        }
    }
}

/// The side of a crack a split particle belongs to (SPEC §9): the crack
/// vertex `vertex` it was split at, the crack path's unit directions into
/// (`incoming`) and out of (`outgoing`) that vertex, and which side of the
/// path (`left` of the direction of growth, or right) the particle lies on.
/// Within `reach` of the vertex (the length of the shorter adjacent crack
/// segment) the particle is visible only from its own side; farther away
/// the crack segments themselves decide (see `fracture::visibility`).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FaceSide {
    /// Reference position of the crack vertex, m.
    pub vertex: Vec2,
    /// Unit direction of the crack path arriving at the vertex.
    pub incoming: Vec2,
    /// Unit direction of the crack path leaving the vertex.
    pub outgoing: Vec2,
    /// On the left of the path (seen along the direction of growth).
    pub left: bool,
    /// Radius around the vertex within which the side test applies, m.
    pub reach: Real,
}

/// All particles of all deformable bodies.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Particles {
    /// Reference position `X_I`, m.
    pub x0: Vec<Vec2>,
    /// Generalized displacement `U_I`, m (not the physical displacement: SPEC §2).
    pub u: Vec<Vec2>,
    /// Generalized velocity `V_I`, m/s (at the half step between output instants).
    pub v: Vec<Vec2>,
    /// Acceleration `A_I` of the last step, m/s².
    pub a: Vec<Vec2>,
    /// Internal force `f_int`, N (per unit depth in plane strain).
    pub f_int: Vec<Vec2>,
    /// External force (contact, loads), N.
    pub f_ext: Vec<Vec2>,
    /// Lumped mass `m_I`, kg (per unit depth in plane strain), including
    /// `added_mass`.
    pub mass: Vec<Real>,
    /// Mass added to `m_I` by mass scaling, kg ([`crate::stability`],
    /// `[time] mass_scaling`; zero without it): kept across the re-lumping
    /// at a crack change, and halved with the mass at a split.
    pub added_mass: Vec<Real>,
    /// Nodal volume `ΔV_I` used in the RK sums, m³ (m² per unit depth in plane strain,
    /// the area in axisymmetry: the kernel weight is a 2D measure).
    pub volume: Vec<Real>,
    /// Local particle spacing `h_I` (the larger of the two directions), m.
    pub spacing: Vec<Real>,
    /// RK support size `a_I`, m (half-width of the square window).
    pub support: Vec<Real>,
    /// Temperature, K (projection of the quadrature temperatures).
    pub temperature: Vec<Real>,
    /// Body index.
    pub body: Vec<u32>,
    /// Role flags.
    pub flags: Vec<ParticleFlags>,
    /// Crack side of a particle created by splitting (SPEC §9); `None` for
    /// every particle not on a crack face.
    pub face_side: Vec<Option<FaceSide>>,
}

impl Particles {
    pub fn len(&self) -> usize {
        self.x0.len()
    }
    pub fn is_empty(&self) -> bool {
        self.x0.is_empty()
    }

    /// Whether every column has one entry per particle (a check of a store
    /// read from a checkpoint; a column added to the store fails to compile
    /// here until it is listed).
    pub fn columns_agree(&self) -> bool {
        let Particles {
            x0,
            u,
            v,
            a,
            f_int,
            f_ext,
            mass,
            added_mass,
            volume,
            spacing,
            support,
            temperature,
            body,
            flags,
            face_side,
        } = self;
        let n = x0.len();
        [
            u.len(),
            v.len(),
            a.len(),
            f_int.len(),
            f_ext.len(),
            mass.len(),
            added_mass.len(),
            volume.len(),
            spacing.len(),
            support.len(),
            temperature.len(),
            body.len(),
            flags.len(),
            face_side.len(),
        ]
        .iter()
        .all(|&l| l == n)
    }

    /// Append one particle at rest.
    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        x0: Vec2,
        volume: Real,
        spacing: Real,
        support: Real,
        temperature: Real,
        body: u32,
        flags: ParticleFlags,
    ) -> usize {
        self.x0.push(x0);
        self.u.push(Vec2::zeros());
        self.v.push(Vec2::zeros());
        self.a.push(Vec2::zeros());
        self.f_int.push(Vec2::zeros());
        self.f_ext.push(Vec2::zeros());
        self.mass.push(0.0);
        self.added_mass.push(0.0);
        self.volume.push(volume);
        self.spacing.push(spacing);
        self.support.push(support);
        self.temperature.push(temperature);
        self.body.push(body);
        self.flags.push(flags);
        self.face_side.push(None);
        self.len() - 1
    }

    /// Append an exact copy of particle `i` (every column) and return its
    /// index. Particle splitting (SPEC §9) starts here and then sets what
    /// differs (position, volume, mass, acceleration); a column added to
    /// the store is copied without the splitter knowing about it.
    pub fn split(&mut self, i: usize) -> usize {
        fn c<T: Copy>(v: &mut Vec<T>, i: usize) {
            let x = v[i];
            v.push(x);
        }
        c(&mut self.x0, i);
        c(&mut self.u, i);
        c(&mut self.v, i);
        c(&mut self.a, i);
        c(&mut self.f_int, i);
        c(&mut self.f_ext, i);
        c(&mut self.mass, i);
        c(&mut self.added_mass, i);
        c(&mut self.volume, i);
        c(&mut self.spacing, i);
        c(&mut self.support, i);
        c(&mut self.temperature, i);
        c(&mut self.body, i);
        c(&mut self.flags, i);
        c(&mut self.face_side, i);
        self.len() - 1
    }

    /// Reorder every column so that new index `k` holds old particle `order[k]`.
    pub fn permute(&mut self, order: &[usize]) {
        fn p<T: Copy>(v: &mut Vec<T>, order: &[usize]) {
            let n: Vec<T> = order.iter().map(|&i| v[i]).collect();
            *v = n;
        }
        p(&mut self.x0, order);
        p(&mut self.u, order);
        p(&mut self.v, order);
        p(&mut self.a, order);
        p(&mut self.f_int, order);
        p(&mut self.f_ext, order);
        p(&mut self.mass, order);
        p(&mut self.added_mass, order);
        p(&mut self.volume, order);
        p(&mut self.spacing, order);
        p(&mut self.support, order);
        p(&mut self.temperature, order);
        p(&mut self.body, order);
        p(&mut self.flags, order);
        p(&mut self.face_side, order);
    }

    /// Total mass, kg.
    pub fn total_mass(&self) -> Real {
        self.mass.iter().sum()
    }

    /// Total linear momentum `Σ m_I V_I`.
    pub fn momentum(&self) -> Vec2 {
        self.mass.iter().zip(&self.v).fold(Vec2::zeros(), |acc, (m, v)| acc + v * *m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_copies_every_column_and_permute_moves_face_sides() {
        let mut p = Particles::default();
        p.push(Vec2::new(1.0, 2.0), 0.5, 0.1, 0.2, 300.0, 0, ParticleFlags(ParticleFlags::SLAVE));
        p.u[0] = Vec2::new(1e-3, 0.0);
        p.v[0] = Vec2::new(3.0, 4.0);
        p.mass[0] = 7.0;
        p.face_side[0] = Some(FaceSide {
            vertex: Vec2::zeros(),
            incoming: Vec2::new(0.0, -1.0),
            outgoing: Vec2::new(0.0, -1.0),
            left: true,
            reach: 0.1,
        });
        let k = p.split(0);
        assert_eq!(k, 1);
        assert_eq!((p.x0[1], p.u[1], p.v[1], p.mass[1]), (p.x0[0], p.u[0], p.v[0], p.mass[0]));
        assert_eq!((p.volume[1], p.spacing[1], p.support[1], p.temperature[1]), (0.5, 0.1, 0.2, 300.0));
        assert_eq!((p.body[1], p.flags[1], p.face_side[1]), (p.body[0], p.flags[0], p.face_side[0]));
        p.face_side[1] = None;
        p.permute(&[1, 0]);
        assert!(p.face_side[0].is_none() && p.face_side[1].is_some());
    }
}
