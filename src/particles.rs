//! The particle store (SPEC §4): struct-of-arrays, one owner for every
//! per-particle field.
//!
//! Every field is indexed by particle number `i` in `0..len()`. Anything that
//! adds, splits or permutes particles goes through the methods here so that
//! no column is forgotten.

use crate::math::{Real, Vec2};

/// Bit flags describing a particle's role.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
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

/// All particles of all deformable bodies.
#[derive(Clone, Debug, Default)]
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
    /// Lumped mass `m_I`, kg (per unit depth in plane strain).
    pub mass: Vec<Real>,
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
}

impl Particles {
    pub fn len(&self) -> usize {
        self.x0.len()
    }
    pub fn is_empty(&self) -> bool {
        self.x0.is_empty()
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
        self.volume.push(volume);
        self.spacing.push(spacing);
        self.support.push(support);
        self.temperature.push(temperature);
        self.body.push(body);
        self.flags.push(flags);
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
        p(&mut self.volume, order);
        p(&mut self.spacing, order);
        p(&mut self.support, order);
        p(&mut self.temperature, order);
        p(&mut self.body, order);
        p(&mut self.flags, order);
    }

    /// Total mass, kg.
    pub fn total_mass(&self) -> Real {
        self.mass.iter().sum()
    }

    /// Total linear momentum `Σ m_I V_I`.
    pub fn momentum(&self) -> Vec2 {
        self.mass
            .iter()
            .zip(&self.v)
            .fold(Vec2::zeros(), |acc, (m, v)| acc + v * *m)
    }
}
