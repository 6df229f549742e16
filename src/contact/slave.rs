//! The contact slave set (SPEC §8): the target particles tested against the
//! master surfaces, with the last pairing of each as a search hint.
//!
//! Which particles are slaves is owned by the particle store (the
//! [`ParticleFlags::SLAVE`] flag); a [`SlaveSet`] is the index list derived
//! from it plus a per-slave cache of the last pairing. The cache is only a
//! hint: clearing it changes no result beyond reusing a pairing (see
//! `search`). After particles are split or permuted, rebuild the set
//! ([`SlaveSet::from_flags`]) or remap it ([`SlaveSet::permute`]).

use super::surface::{detect_surface, SurfaceDetection};
use super::ContactError;
use crate::math::{Real, Vec2};
use crate::particles::ParticleFlags;

/// A feature of a master outline that a slave is paired with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum MasterFeature {
    /// Segment `k`, from vertex `k` to vertex `k + 1`.
    Segment(u32),
    /// Vertex `k`, used with the vertex normal when the slave projects
    /// onto neither adjacent segment (a convex corner seen from outside, or
    /// the inside of a concave one).
    Vertex(u32),
}

/// The pairing of a slave with a master feature of a rigid body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct Pairing {
    /// Index of the rigid body.
    pub body: u32,
    /// The feature of its outline.
    pub feature: MasterFeature,
}

/// The slave particles, ascending and unique, with each one's last pairing.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SlaveSet {
    /// Particle index of slave `k`.
    particles: Vec<u32>,
    /// Last pairing of slave `k` (`None`: not near any master last step).
    pairing: Vec<Option<Pairing>>,
}

impl SlaveSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// The given particles (duplicates ignored).
    pub fn from_indices(indices: impl IntoIterator<Item = usize>) -> Self {
        let mut s = Self::new();
        for i in indices {
            s.add(i);
        }
        s
    }

    /// The particles flagged [`ParticleFlags::SLAVE`].
    pub fn from_flags(flags: &[ParticleFlags]) -> Self {
        let particles: Vec<u32> =
            (0..flags.len()).filter(|&i| flags[i].has(ParticleFlags::SLAVE)).map(|i| i as u32).collect();
        let pairing = vec![None; particles.len()];
        Self { particles, pairing }
    }

    /// The surface particles of a particle set, found geometrically
    /// ([`detect_surface`]).
    pub fn detect(positions: &[Vec2], spacing: &[Real], params: &SurfaceDetection) -> Result<Self, ContactError> {
        Ok(Self::from_indices(detect_surface(positions, spacing, params)?))
    }

    /// The surface particles of each body of a particle set, found
    /// geometrically body by body ([`detect_surface`] on the particles of
    /// `body[i] == b`): bodies that touch do not hide each other's surface.
    /// The same set as [`Self::detect`] for one body.
    pub fn detect_per_body(
        positions: &[Vec2],
        spacing: &[Real],
        body: &[u32],
        params: &SurfaceDetection,
    ) -> Result<Self, ContactError> {
        if body.len() != positions.len() {
            return Err(ContactError::LengthMismatch { field: "body", expected: positions.len(), found: body.len() });
        }
        if spacing.len() != positions.len() {
            return Err(ContactError::LengthMismatch {
                field: "spacing",
                expected: positions.len(),
                found: spacing.len(),
            });
        }
        let mut bodies: Vec<u32> = body.to_vec();
        bodies.sort_unstable();
        bodies.dedup();
        if bodies.len() <= 1 {
            return Self::detect(positions, spacing, params);
        }
        let mut set = Self::new();
        for b in bodies {
            let members: Vec<usize> = (0..positions.len()).filter(|&i| body[i] == b).collect();
            let x: Vec<Vec2> = members.iter().map(|&i| positions[i]).collect();
            let h: Vec<Real> = members.iter().map(|&i| spacing[i]).collect();
            for k in detect_surface(&x, &h, params)? {
                set.add(members[k]);
            }
        }
        Ok(set)
    }

    /// Add particle `i` (e.g. a new crack-face particle). Returns `false`
    /// if it was already a slave.
    pub fn add(&mut self, i: usize) -> bool {
        let i = i as u32;
        match self.particles.binary_search(&i) {
            Ok(_) => false,
            Err(k) => {
                self.particles.insert(k, i);
                self.pairing.insert(k, None);
                true
            }
        }
    }

    /// Whether particle `i` is a slave.
    pub fn contains(&self, i: usize) -> bool {
        self.particles.binary_search(&(i as u32)).is_ok()
    }

    /// Number of slaves.
    pub fn len(&self) -> usize {
        self.particles.len()
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.particles.is_empty()
    }

    /// Particle indices, ascending.
    pub fn particles(&self) -> &[u32] {
        &self.particles
    }

    /// Last pairing of slave `k` (position in [`Self::particles`]).
    pub fn pairing(&self, k: usize) -> Option<Pairing> {
        self.pairing.get(k).copied().flatten()
    }

    /// Last pairing of particle `i`, if it is a slave and was paired.
    pub fn pairing_of_particle(&self, i: usize) -> Option<Pairing> {
        self.particles.binary_search(&(i as u32)).ok().and_then(|k| self.pairing[k])
    }

    /// Record the pairing of slave `k`.
    pub(crate) fn set_pairing(&mut self, k: usize, p: Option<Pairing>) {
        self.pairing[k] = p;
    }

    /// Forget every pairing (the next search starts from scratch).
    pub fn clear_pairings(&mut self) {
        self.pairing.fill(None);
    }

    /// Set [`ParticleFlags::SLAVE`] on every slave in `flags`.
    pub fn mark_flags(&self, flags: &mut [ParticleFlags]) -> Result<(), ContactError> {
        self.check_indices(flags.len())?;
        for &i in &self.particles {
            flags[i as usize].set(ParticleFlags::SLAVE);
        }
        Ok(())
    }

    /// Follow [`crate::particles::Particles::permute`]: new particle `k` is
    /// old particle `order[k]`. Pairings move with their particles.
    pub fn permute(&mut self, order: &[usize]) -> Result<(), ContactError> {
        let mut new_of_old = vec![u32::MAX; order.len()];
        for (k, &old) in order.iter().enumerate() {
            if old >= order.len() || new_of_old[old] != u32::MAX {
                return Err(ContactError::InvalidPermutation { position: k });
            }
            new_of_old[old] = k as u32;
        }
        self.check_indices(order.len())?;
        let mut pairs: Vec<(u32, Option<Pairing>)> =
            self.particles.iter().zip(&self.pairing).map(|(&i, &p)| (new_of_old[i as usize], p)).collect();
        pairs.sort_unstable_by_key(|&(i, _)| i);
        self.particles = pairs.iter().map(|&(i, _)| i).collect();
        self.pairing = pairs.iter().map(|&(_, p)| p).collect();
        Ok(())
    }

    /// Error if a slave index is not below `n` particles.
    pub fn check_indices(&self, n: usize) -> Result<(), ContactError> {
        match self.particles.last() {
            Some(&i) if i as usize >= n => Err(ContactError::SlaveOutOfRange { particle: i as usize, particles: n }),
            _ => Ok(()),
        }
    }

    /// Error unless the set is whole: the particles ascending, unique and
    /// below `n`, one pairing per slave, each pairing naming a body (of
    /// `vertices[b]` vertices, as many segments) and one of its features.
    pub fn check(&self, n: usize, vertices: &[usize]) -> Result<(), ContactError> {
        self.check_indices(n)?;
        if let Some(k) = self.particles.windows(2).position(|w| w[0] >= w[1]) {
            return Err(ContactError::InvalidSlave { slave: k + 1, reason: "particles not ascending" });
        }
        if self.pairing.len() != self.particles.len() {
            return Err(ContactError::LengthMismatch {
                field: "pairing",
                expected: self.particles.len(),
                found: self.pairing.len(),
            });
        }
        for (k, p) in self.pairing.iter().enumerate() {
            if let Some(Pairing { body, feature: MasterFeature::Segment(f) | MasterFeature::Vertex(f) }) = *p {
                if vertices.get(body as usize).is_none_or(|&nv| f as usize >= nv) {
                    return Err(ContactError::InvalidSlave {
                        slave: k,
                        reason: "paired with a feature that does not exist",
                    });
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn add_keeps_sorted_unique_and_remembers_pairings() {
        let mut s = SlaveSet::from_indices([5, 1, 3, 1]);
        assert_eq!(s.particles(), &[1, 3, 5]);
        s.set_pairing(1, Some(Pairing { body: 0, feature: MasterFeature::Segment(2) }));
        assert!(s.add(4));
        assert!(!s.add(3));
        assert_eq!(s.particles(), &[1, 3, 4, 5]);
        assert_eq!(s.pairing_of_particle(3), Some(Pairing { body: 0, feature: MasterFeature::Segment(2) }));
        assert_eq!(s.pairing_of_particle(4), None);
    }

    #[test]
    fn permute_follows_the_particle_store() {
        let mut s = SlaveSet::from_indices([0, 2]);
        s.set_pairing(1, Some(Pairing { body: 0, feature: MasterFeature::Vertex(1) }));
        // new 0 = old 2, new 1 = old 0, new 2 = old 1
        s.permute(&[2, 0, 1]).unwrap();
        assert_eq!(s.particles(), &[0, 1]);
        assert_eq!(s.pairing_of_particle(0), Some(Pairing { body: 0, feature: MasterFeature::Vertex(1) }));
        assert!(s.permute(&[0, 0, 1]).is_err());
    }

    #[test]
    fn flags_round_trip() {
        let s = SlaveSet::from_indices([1, 3]);
        let mut flags = vec![ParticleFlags::default(); 4];
        s.mark_flags(&mut flags).unwrap();
        assert_eq!(SlaveSet::from_flags(&flags).particles(), s.particles());
        assert!(s.mark_flags(&mut flags[..3]).is_err());
    }
}
