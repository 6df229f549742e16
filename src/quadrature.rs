//! The quadrature-point store (SPEC §4): integration points of the background
//! cells, each with its weight and its material state, struct-of-arrays.

use crate::material::PointState;
use crate::math::{Block2, InPlane, Real, Tensor3, Vec2};

/// All quadrature points of all bodies. Index `q` in `0..len()`.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct QuadraturePoints {
    /// Reference position `X_q`, m.
    pub x0: Vec<Vec2>,
    /// Integration weight `w_q` including the geometry factor
    /// (cell area × Gauss weight, × 2πR_q in axisymmetry), m³ (m² per unit depth).
    pub weight: Vec<Real>,
    /// Length of the point's background cell in the reference lattice,
    /// `√(Δx Δy)`, m: the `L₀` of the bulk viscosity
    /// ([`crate::bulk_viscosity`]).
    pub length: Vec<Real>,
    /// Body index (selects the material).
    pub body: Vec<u32>,
    /// Current deformation gradient `F`, in the block form of 2D kinematics
    /// (SPEC §2: no out-of-plane shear; [`Block2`], 40 bytes a point
    /// instead of 72, which the material sweep reads and writes every step).
    pub f: Vec<Block2>,
    /// Kirchhoff stress `τ`, Pa, in block form like `F` (the material models
    /// keep it: their updates of a block-form stress under block-form
    /// kinematics are block-form).
    pub tau: Vec<Block2>,
    /// Equivalent plastic strain.
    pub eps_p: Vec<Real>,
    /// Equivalent plastic strain rate, 1/s.
    pub eps_p_rate: Vec<Real>,
    /// Temperature, K.
    pub temperature: Vec<Real>,
    /// Johnson–Cook damage.
    pub damage: Vec<Real>,
    /// The stress triaxiality integrated over the plastic strain,
    /// `∫ η dε̄` (`η = σ_m/σ_eq` at each step's end;
    /// [`crate::material::strain_path_increment`]): divided by `ε̄` it is
    /// the average triaxiality of the point's strain path, the output
    /// field `average_triaxiality`. The mechanics and the crack criteria
    /// do not read it (a crack gate on it was tried: `docs/validation.md`,
    /// "The compression gate read over the strain path").
    pub triaxiality_strain: Vec<Real>,
    /// First Piola–Kirchhoff stress times the weight, `P w_q`, cached for the
    /// force gather, N·m (per unit depth): its in-plane block, aligned for
    /// the gather's scattered reads ([`InPlane`]), and its out-of-plane
    /// entry in [`QuadraturePoints::pw_zz`] (the hoop term of
    /// axisymmetry): the only entries the force reads (SPEC §4).
    pub pw: Vec<InPlane>,
    /// The out-of-plane entry `(P w)_zz` (`θθ` in axisymmetry).
    pub pw_zz: Vec<Real>,
    /// Where point `q`'s deformation gradient carries a jump over crack
    /// changes: an index into [`QuadraturePoints::f_carry`], or
    /// [`NO_CARRY`]. `F = I + Σ_I u_I ⊗ ∇N_I(X_q) + f_carry[slot]`
    /// (`crate::fracture` module doc, "deformation gradient across a crack
    /// change").
    pub f_carry_slot: Vec<u32>,
    /// The carried jumps, one per point that has one (few: the points next
    /// to crack paths).
    pub f_carry: Vec<Tensor3>,
    /// Eroded: the point inverted after meeting the crack criterion, was
    /// torn open after fracturing (`crate::material::TORN_VOLUME_RATIO`),
    /// or, fractured, would have set the stable step below the case's
    /// floor (`[time] erode_failed_below`, [`crate::stability`]), and
    /// carries no stress from then on (`crate::fracture` module doc).
    pub eroded: Vec<bool>,
}

/// [`QuadraturePoints::f_carry_slot`] of a point without a carried jump.
pub const NO_CARRY: u32 = u32::MAX;

impl QuadraturePoints {
    pub fn len(&self) -> usize {
        self.x0.len()
    }
    pub fn is_empty(&self) -> bool {
        self.x0.is_empty()
    }

    /// Whether every per-point column has one entry per point and every
    /// carried jump named exists (a check of a store read from a
    /// checkpoint; a column added to the store fails to compile here until
    /// it is listed).
    pub fn columns_agree(&self) -> bool {
        let QuadraturePoints {
            x0,
            weight,
            length,
            body,
            eroded,
            f_carry_slot,
            f_carry,
            f,
            tau,
            pw,
            pw_zz,
            eps_p,
            eps_p_rate,
            temperature,
            damage,
            triaxiality_strain,
        } = self;
        let n = x0.len();
        let columns = [weight.len(), body.len(), eroded.len(), f_carry_slot.len(), f.len(), tau.len(), pw.len()];
        let more_columns = [
            pw_zz.len(),
            eps_p.len(),
            eps_p_rate.len(),
            temperature.len(),
            damage.len(),
            length.len(),
            triaxiality_strain.len(),
        ];
        columns.iter().chain(&more_columns).all(|&l| l == n)
            && f_carry_slot.iter().all(|&s| s == NO_CARRY || (s as usize) < f_carry.len())
    }

    /// Append a point in the given state.
    pub fn push(&mut self, x0: Vec2, weight: Real, length: Real, body: u32, s: &PointState) {
        self.x0.push(x0);
        self.weight.push(weight);
        self.length.push(length);
        self.body.push(body);
        self.f.push(Block2::identity_scaled(1.0));
        self.tau.push(Block2::block_part(&s.tau));
        self.eps_p.push(s.eps_p);
        self.eps_p_rate.push(s.eps_p_rate);
        self.temperature.push(s.temperature);
        self.damage.push(s.damage);
        self.triaxiality_strain.push(0.0);
        let pw = Block2::zeros();
        self.pw.push(pw.in_plane());
        self.pw_zz.push(pw.zz);
        self.f_carry_slot.push(NO_CARRY);
        self.eroded.push(false);
    }

    /// Erode point `q`: it carries no stress (and so no internal force) from
    /// now on; its state stays for the output and the criteria
    /// ([`QuadraturePoints::eroded`]).
    pub fn erode(&mut self, q: usize) {
        self.eroded[q] = true;
        self.tau[q] = Block2::zeros();
        let pw = Block2::zeros();
        self.pw[q] = pw.in_plane();
        self.pw_zz[q] = pw.zz;
    }

    /// Add `jump` to the deformation gradient carried by point `q`.
    pub fn add_f_carry(&mut self, q: usize, jump: &Tensor3) {
        match self.f_carry_slot[q] {
            NO_CARRY => {
                self.f_carry_slot[q] = self.f_carry.len() as u32;
                self.f_carry.push(*jump);
            }
            slot => self.f_carry[slot as usize] += jump,
        }
    }

    /// The deformation gradient carried by point `q` (zero if none).
    pub fn f_carry_of(&self, q: usize) -> Tensor3 {
        match self.f_carry_slot[q] {
            NO_CARRY => Tensor3::zeros(),
            slot => self.f_carry[slot as usize],
        }
    }

    /// `P w_q` of point `q` as one block, from its two columns.
    #[inline]
    pub fn pw_block(&self, q: usize) -> Block2 {
        Block2::from_parts(&self.pw[q], self.pw_zz[q])
    }

    /// The material state of point `q`, gathered from the columns.
    #[inline]
    pub fn state(&self, q: usize) -> PointState {
        PointState {
            tau: self.tau[q].to_tensor(),
            eps_p: self.eps_p[q],
            eps_p_rate: self.eps_p_rate[q],
            temperature: self.temperature[q],
            damage: self.damage[q],
        }
    }
}
