//! The body tracker's settings ([`TrackerOptions`]), their defaults and their checks.

/// Tracker settings.
#[derive(Clone, Debug)]
pub struct TrackerOptions {
    /// Particles per annealing layer (torso and head; the limb stages use half as many again).
    pub particles: usize,
    /// Pyramid level of each annealing layer of a stage (coarse first).
    pub layers: Vec<usize>,
    /// Robust scale σ of the colour difference (grey levels).
    pub robust_sigma: f32,
    /// Cell size of the light mesh (metres).
    pub mesh_cell: f64,
    /// Linear blend skinning instead of rigid.
    pub lbs: bool,
    /// Frames sampled for the background median.
    pub background_frames: usize,
    /// Prediction factor on the last velocity (0 = constant position).
    pub prediction: f64,
    /// Seed of the annealing moves.
    pub seed: u64,
    /// Track at most this many frames (from frame 0).
    pub frames: Option<usize>,
    /// Passes of the stage hierarchy per frame, as factors of the move spreads (a wide
    /// search, then a narrower one that refines the torso with the limbs in place).
    pub passes: Vec<f64>,
    /// Weight of the motion prior (per squared move spread of a parameter).
    pub prior_weight: f64,
    /// Limb stages also start particles from the previous frame's limb pose (no
    /// prediction), the rest pose, and the predicted limb half bent or straightened (see
    /// [`limb_restarts`](super::restarts::limb_restarts)).
    pub limb_restarts: bool,
    /// Start without approximate joints: find the person and their pose from the first
    /// frame's images alone ([`super::auto_start`]); `init_joints.csv` is not read.
    pub auto_start: bool,
    /// Notice a lost track from the image fit and find the body again
    /// ([`super::loss`]); off by default until measured on the dance clips.
    pub recover: bool,
    /// First frame tracked (the start is made there).
    pub first_frame: usize,
    /// Adapt the puppet's proportions to the person at the start ([`super::body_adapt`]).
    pub adapt_body: bool,
    /// Move spread of the pelvis and chest rotations, radians (their motion prior's scale
    /// too). Default 0.08.
    pub torso_spread: f64,
    /// The trunk stage keeps the upper arms and thighs still in the world
    /// ([`Puppet::keep_limbs`](super::puppet::Puppet::keep_limbs)) instead of carrying them with the trunk, and also starts from
    /// the pelvis turned and the chest twisted ([`trunk_restarts`](super::restarts::trunk_restarts)). Default false.
    pub anchor_limbs: bool,
    /// Both hands hold one object (a golf club): the right arm's stage (searched after the
    /// left) pays for wrists more than this many metres apart ([`super::hands_prior`]).
    /// None (default): no such prior.
    pub hands_apart: Option<f64>,
    /// A golfer's straight lead arm: the left arm's stage pays for a left elbow angle below
    /// this (radians, π = straight; [`super::hands_prior`]). None (default): no such prior.
    pub lead_elbow_min: Option<f64>,
    /// The automatic start searches from a golfer's address pose
    /// ([`super::address_pose`]) instead of the rest pose. Default false.
    pub golf_address: bool,
}

impl Default for TrackerOptions {
    fn default() -> Self {
        TrackerOptions {
            particles: 32,
            layers: vec![1, 1, 1, 0, 0],
            robust_sigma: 40.0,
            mesh_cell: super::puppet_mesh::DEFAULT_CELL,
            lbs: false,
            background_frames: 25,
            prediction: 0.7,
            seed: 1,
            frames: None,
            passes: vec![1.0, 0.35],
            prior_weight: 0.05,
            limb_restarts: true,
            auto_start: false,
            recover: false,
            first_frame: 0,
            adapt_body: false,
            torso_spread: 0.08,
            anchor_limbs: false,
            hands_apart: None,
            lead_elbow_min: None,
            golf_address: false,
        }
    }
}

impl TrackerOptions {
    /// Checks the settings; the error says which one is unusable and why.
    pub fn validate(&self) -> Result<(), String> {
        if self.particles < 2 || self.layers.is_empty() {
            return Err(format!(
                "tracker: need at least 2 particles and one layer (got {} and {})",
                self.particles,
                self.layers.len()
            ));
        }
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !positive(self.robust_sigma as f64) || !positive(self.mesh_cell) {
            return Err("tracker: robust_sigma and mesh_cell must be positive".into());
        }
        if !(self.torso_spread.is_finite() && self.torso_spread > 0.0) {
            return Err(format!(
                "tracker: torso_spread must be positive (got {})",
                self.torso_spread
            ));
        }
        if let Some(m) = self
            .lead_elbow_min
            .filter(|m| !(m.is_finite() && (0.0..=std::f64::consts::PI).contains(m)))
        {
            return Err(format!(
                "tracker: lead_elbow_min must be an angle within 0..π radians (got {m})"
            ));
        }
        if let Some(m) = self.hands_apart.filter(|m| !(m.is_finite() && *m > 0.0)) {
            return Err(format!(
                "tracker: hands_apart must be a positive distance in metres (got {m})"
            ));
        }
        if !(self.prior_weight.is_finite() && self.prior_weight >= 0.0) {
            return Err(format!(
                "tracker: prior_weight must be finite and not negative (got {})",
                self.prior_weight
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::TrackerOptions;

    /// Makes one setting unusable.
    type Spoil = fn(&mut TrackerOptions);

    #[test]
    fn the_defaults_pass_and_each_unusable_setting_is_named() {
        assert_eq!(TrackerOptions::default().validate(), Ok(()));
        let bad: [(&str, Spoil); 7] = [
            ("particles", |o| o.particles = 1),
            ("layer", |o| o.layers.clear()),
            ("robust_sigma", |o| o.robust_sigma = f32::NAN),
            ("torso_spread", |o| o.torso_spread = 0.0),
            ("lead_elbow_min", |o| o.lead_elbow_min = Some(4.0)),
            ("hands_apart", |o| o.hands_apart = Some(-0.1)),
            ("prior_weight", |o| o.prior_weight = f64::INFINITY),
        ];
        for (name, spoil) in bad {
            let mut o = TrackerOptions::default();
            spoil(&mut o);
            let e = o.validate().expect_err(name);
            assert!(e.contains(name), "{name}: {e}");
        }
    }
}
