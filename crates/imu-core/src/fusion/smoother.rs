//! Forward–backward (Rauch–Tung–Striebel) smoothing of the error-state filter.
//!
//! The forward filter, asked to ([`super::Eskf::with_smoothing`]), hands out one
//! [`EpochRecord`] per *epoch*: each time at which it corrected its state (all the updates at
//! one time are one epoch), and at least every `max_gap_s` of propagation without one (so that a
//! GNSS outage is smoothed at that spacing). A record holds the transition `Φ` from the previous
//! epoch's corrected state to this epoch's predicted one (the product of the covariance steps in
//! between), the predicted covariance `P⁻`, the corrected one `P⁺` and the correction `δx` the
//! filter injected.
//!
//! [`rts_backward`] then runs the smoother backwards over the records. With the gain
//! `C_j = P⁺_j Φ_{j+1}ᵀ (P⁻_{j+1})⁻¹`, the smoothed correction relative to the filter's
//! corrected state at epoch `j` and its covariance are
//! `δs_j = C_j (δx_{j+1} + δs_{j+1})` and `P_{j|N} = P⁺_j + C_j (P_{j+1|N} − P⁻_{j+1}) C_jᵀ`,
//! from `δs_N = 0`, `P_{N|N} = P⁺_N` — closed-loop error states: the filter's predicted error
//! is zero, so `δx_{j+1} + δs_{j+1}` is the smoothed error relative to the prediction. A reset
//! of the filter to the fixes ([`super::Eskf::reset_to_gnss`]) breaks the chain: the epoch
//! before it keeps the filter's estimate.
use nalgebra::{SMatrix, SVector};

/// An error covariance of `S` states.
pub type Covariance<const S: usize> = SMatrix<f64, S, S>;

/// An error-state vector of `S` states.
pub type ErrorVector<const S: usize> = SVector<f64, S>;

/// What the backward pass needs of one epoch of the forward filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EpochRecord<const S: usize> {
    /// The epoch's time, s.
    pub t_s: f64,
    /// Transition from the previous epoch's corrected state to this epoch's prediction.
    pub phi: Covariance<S>,
    /// Predicted covariance (before this epoch's updates).
    pub prior: Covariance<S>,
    /// Corrected covariance (after them).
    pub posterior: Covariance<S>,
    /// The corrections injected at this epoch, summed.
    pub correction: ErrorVector<S>,
    /// Whether the filter was reset to a fix here (the smoother does not cross it).
    pub reset: bool,
}

/// The forward filter's bookkeeping for the smoother.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SmoothingLog<const S: usize> {
    max_gap_s: f64,
    /// Product of the covariance steps since the last epoch.
    phi: Covariance<S>,
    /// Propagation time since the last epoch, s.
    gap_s: f64,
    /// The epoch being gathered: its time, prior, corrections and reset flag.
    open: Option<(f64, Covariance<S>, ErrorVector<S>, bool)>,
    /// Phi of the open epoch (the transition that led to it).
    open_phi: Covariance<S>,
    /// Finished records not yet taken (at most two: one closed by a step, one at the end).
    ready: [Option<EpochRecord<S>>; 2],
}

impl<const S: usize> SmoothingLog<S> {
    /// A log whose first epoch is the start at `t_s` with covariance `p0`.
    pub(crate) fn new(max_gap_s: f64, t_s: f64, p0: &Covariance<S>) -> Self {
        Self {
            max_gap_s,
            phi: Covariance::identity(),
            gap_s: 0.0,
            open: Some((t_s, *p0, ErrorVector::zeros(), false)),
            open_phi: Covariance::identity(),
            ready: [None, None],
        }
    }

    fn push(&mut self, record: EpochRecord<S>) {
        if let Some(slot) = self.ready.iter_mut().find(|r| r.is_none()) {
            *slot = Some(record);
        }
    }

    /// Closes the open epoch with `posterior`, if one is open.
    fn close(&mut self, posterior: &Covariance<S>) {
        if let Some((t_s, prior, correction, reset)) = self.open.take() {
            let record = EpochRecord {
                t_s,
                phi: self.open_phi,
                prior,
                posterior: *posterior,
                correction,
                reset,
            };
            self.push(record);
            self.phi = Covariance::identity();
            self.gap_s = 0.0;
        }
    }

    /// Before a covariance step of `phi_step` over `dt` from covariance `p` (the corrected one
    /// if an epoch is open): closes it. After the step (`p_after`), opens an epoch when the
    /// propagation since the last one reaches the gap.
    pub(crate) fn step(
        &mut self,
        p_before: &Covariance<S>,
        phi_step: &Covariance<S>,
        dt: f64,
        p_after: &Covariance<S>,
        t_s: f64,
    ) {
        self.close(p_before);
        self.phi = phi_step * self.phi;
        self.gap_s += dt;
        if self.gap_s >= self.max_gap_s {
            self.open_epoch(t_s, p_after);
        }
    }

    fn open_epoch(&mut self, t_s: f64, prior: &Covariance<S>) {
        if self.open.is_none() {
            self.open = Some((t_s, *prior, ErrorVector::zeros(), false));
            self.open_phi = self.phi;
            self.phi = Covariance::identity();
            self.gap_s = 0.0;
        }
    }

    /// A correction `dx` about to be injected at `t_s`, the covariance before it `prior`.
    pub(crate) fn correction(
        &mut self,
        t_s: f64,
        prior: &Covariance<S>,
        dx: &ErrorVector<S>,
        reset: bool,
    ) {
        self.open_epoch(t_s, prior);
        if let Some(open) = self.open.as_mut() {
            open.2 += dx;
            open.3 |= reset;
        }
    }

    /// The end of the run at covariance `p` and time `t_s`: the open epoch closed, and an epoch
    /// for the propagation since the last one.
    pub(crate) fn finish(&mut self, t_s: f64, p: &Covariance<S>) {
        self.close(p);
        if self.gap_s > 0.0 {
            self.open_epoch(t_s, p);
            self.close(p);
        }
    }

    /// The next finished record.
    pub(crate) fn take(&mut self) -> Option<EpochRecord<S>> {
        let first = self.ready[0].take();
        if first.is_some() {
            self.ready[0] = self.ready[1].take();
        }
        first
    }
}

/// Where the backward pass reads the forward filter's epochs from, in time order: a slice of
/// records, or a store that keeps them packed (symmetric covariances by their upper triangle).
pub trait Epochs<const S: usize> {
    /// How many epochs.
    fn count(&self) -> usize;
    /// Epoch `j` (`j < count()`).
    fn record(&self, j: usize) -> EpochRecord<S>;
}

impl<const S: usize> Epochs<S> for [EpochRecord<S>] {
    fn count(&self) -> usize {
        self.len()
    }

    fn record(&self, j: usize) -> EpochRecord<S> {
        self[j]
    }
}

/// The backward pass over `epochs`: for each epoch `j`, from the last to the first,
/// `visit(j, δs_j, P_{j|N})` — the smoothed correction to the filter's corrected state at
/// epoch `j` and its covariance. Only the pass's running covariance is held, so the caller keeps
/// what it needs of each (its diagonal, say). Where the predicted covariance of the next epoch
/// cannot be inverted, or the next epoch is a reset, the epoch keeps the filter's estimate.
pub fn rts_backward<const S: usize, E: Epochs<S> + ?Sized>(
    epochs: &E,
    mut visit: impl FnMut(usize, &ErrorVector<S>, &Covariance<S>),
) {
    let n = epochs.count();
    if n == 0 {
        return;
    }
    let mut next = epochs.record(n - 1);
    let mut smoothed = ErrorVector::<S>::zeros();
    let mut covariance = next.posterior;
    visit(n - 1, &smoothed, &covariance);
    for j in (0..n - 1).rev() {
        let here = epochs.record(j);
        let gain = if next.reset {
            None
        } else {
            next.prior.cholesky().map(|chol| {
                // C = P⁺ Φᵀ (P⁻)⁻¹ = ((P⁻)⁻¹ Φ P⁺)ᵀ, P⁻ and P⁺ symmetric.
                chol.solve(&(next.phi * here.posterior)).transpose()
            })
        };
        match gain {
            Some(c) => {
                smoothed = c * (next.correction + smoothed);
                let p = here.posterior + c * (covariance - next.prior) * c.transpose();
                covariance = (p + p.transpose()) * 0.5;
            }
            None => {
                smoothed = ErrorVector::zeros();
                covariance = here.posterior;
            }
        }
        visit(j, &smoothed, &covariance);
        next = here;
    }
}
