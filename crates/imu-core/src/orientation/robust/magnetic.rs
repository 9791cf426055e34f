//! The robust filter's magnetic disturbance test: the field's magnitude and dip, seen in the
//! Earth frame the accelerometer and gyroscope give, against a reference learnt while the field
//! is undisturbed (in the way of VQF's magnetic disturbance rejection, Laidig & Seel 2023).
//!
//! - A reading whose low-passed magnitude is off the reference by more than
//!   `mag_rejection` (fraction) or whose dip is off by more than `dip_rejection_rad` is
//!   disturbed; it stays so until the field has agreed for `mag_min_undisturbed_s`.
//! - While disturbed the heading is not corrected, for at most `mag_max_rejection_s` in all;
//!   after that the correction runs at `1/mag_rejection_factor` of its gain (a heading held on
//!   the gyroscope alone for ever drifts too).
//! - A new field is accepted as the reference when a steady candidate has been seen for
//!   `mag_new_time_s` of rotation faster than `mag_new_min_rate_rad_s` (a magnet fixed to
//!   the sensor turns with it and never looks steady in the Earth frame; the Earth's field in a
//!   new place does). The first reference needs `mag_new_first_time_s` of a steady field, turning
//!   or not.
use super::RobustParams;
use super::lowpass::LowPass;
use crate::math;

#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct MagneticTest {
    current: LowPass<2>,
    reference: Option<(f64, f64)>,
    candidate: (f64, f64),
    candidate_s: f64,
    undisturbed_s: f64,
    rejected_s: f64,
    disturbed: bool,
}

impl MagneticTest {
    pub(crate) fn new(p: &RobustParams, dt_s: f64) -> Self {
        Self {
            current: LowPass::new(p.mag_current_tau_s, dt_s),
            reference: None,
            candidate: (0.0, 0.0),
            candidate_s: 0.0,
            undisturbed_s: 0.0,
            rejected_s: 0.0,
            disturbed: true,
        }
    }

    pub(crate) fn disturbed(&self) -> bool {
        self.disturbed
    }

    /// One reading of magnitude `norm` (µT) and dip `dip` (rad, down positive), with the body
    /// turning at `rate_rad_s`; `k_ref` is `1 − e^(−Δt/mag_reference_tau_s)`. Returns the
    /// factor (0 to 1) on the heading correction's gain.
    pub(crate) fn step(
        &mut self,
        p: &RobustParams,
        norm: f64,
        dip: f64,
        rate_rad_s: f64,
        k_ref: f64,
        dt_s: f64,
    ) -> f64 {
        let [norm, dip] = self.current.step([norm, dip], dt_s);
        let close = |(n, d): (f64, f64)| {
            math::abs(norm - n) < p.mag_rejection * n && math::abs(dip - d) < p.dip_rejection_rad
        };
        match self.reference {
            Some(r) if close(r) => {
                self.undisturbed_s += dt_s;
                if self.undisturbed_s >= p.mag_min_undisturbed_s {
                    self.disturbed = false;
                    self.reference = Some((r.0 + k_ref * (norm - r.0), r.1 + k_ref * (dip - r.1)));
                }
            }
            _ => {
                self.undisturbed_s = 0.0;
                self.disturbed = true;
            }
        }
        // A candidate for a new reference.
        if close(self.candidate) {
            // The first reference needs only a steady field; a new one, a field that stays
            // steady while the body turns (which a magnet fixed to the body does not).
            if rate_rad_s >= p.mag_new_min_rate_rad_s || self.reference.is_none() {
                self.candidate_s += dt_s;
            }
            let c = self.candidate;
            self.candidate = (c.0 + k_ref * (norm - c.0), c.1 + k_ref * (dip - c.1));
            let needed = if self.reference.is_some() {
                p.mag_new_time_s
            } else {
                p.mag_new_first_time_s
            };
            if self.disturbed && self.candidate_s >= needed {
                self.reference = Some(self.candidate);
                self.disturbed = false;
                self.undisturbed_s = p.mag_min_undisturbed_s;
            }
        } else {
            self.candidate_s = 0.0;
            self.candidate = (norm, dip);
        }
        if self.disturbed {
            if self.rejected_s <= p.mag_max_rejection_s {
                self.rejected_s += dt_s;
                0.0
            } else {
                1.0 / p.mag_rejection_factor
            }
        } else {
            self.rejected_s = (self.rejected_s - p.mag_rejection_factor * dt_s).max(0.0);
            1.0
        }
    }
}
