//! A fusion as a front end states it ([`FuseRequest`]) and where the filter starts
//! ([`Start`]).
use super::{FuseSetup, Gate};
use crate::choice::{Choice, display_as_name};
use crate::error::{RequestOption, Result, refused};
use crate::io::conventions::EarthName;
use crate::run::navigate::InitialState;

/// Where the filter starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start<'a> {
    /// At the first IMU sample, in this state (a truth row).
    State(&'a InitialState),
    /// Without truth: at the first GNSS fix whose horizontal speed is at least
    /// [`ALIGN_MIN_SPEED_M_S`](super::ALIGN_MIN_SPEED_M_S), with position and velocity from the fix and the attitude of a
    /// vehicle moving nose first (heading and pitch along the fix's velocity, roll 0), each
    /// with its stated one-sigma (see [`gnss_alignment_sigma`](super::gnss_alignment_sigma)); the estimate begins there.
    AlignGnss,
    /// Without truth, at rest, on the WGS-84 Earth: levelling from the mean specific force and
    /// gyrocompassing from the mean body rate (the Earth rate's horizontal part points north)
    /// over the first `duration_s`, position from the fixes; the estimate begins at its end.
    /// Refused on the flat Earth, whose model has no Earth rate.
    AlignStatic {
        /// How long the vehicle stands still at the start, s.
        duration_s: f64,
    },
    /// Without truth or heading, at rest (a walk, a hand-held log): levelled from the mean
    /// specific force over the rest at the start (given or found), heading zero — the frame's
    /// axes are the body's heading at the start, so its one-sigma is 0 — velocity zero, on the
    /// flat Earth at the origin (on WGS-84 at the first fix); the estimate begins at the
    /// rest's end.
    Level,
}

/// How long `--align static` averages, s.
pub const STATIC_ALIGN_S: f64 = 60.0;

/// An alignment by name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AlignName {
    /// [`Start::AlignGnss`].
    #[default]
    Gnss,
    /// [`Start::AlignStatic`] over [`STATIC_ALIGN_S`].
    Static,
    /// [`Start::Level`].
    Level,
}

impl Choice for AlignName {
    const WHAT: &'static str = "alignment";
    const NAMES: &'static [(&'static str, Self)] = &[
        ("gnss", Self::Gnss),
        ("static", Self::Static),
        ("level", Self::Level),
    ];
}

display_as_name!(AlignName);

impl<'a> Start<'a> {
    /// The start a front end's two options give (`--init`/`--align`, Python's `initial=`/
    /// `align=`): the truth row or the alignment; `None` for neither.
    ///
    /// # Errors
    /// Both (field `initial`).
    pub fn of(initial: Option<&'a InitialState>, align: Option<AlignName>) -> Result<Option<Self>> {
        match (initial, align) {
            (Some(_), Some(_)) => Err(refused(
                RequestOption::Initial,
                "give the initial state or an alignment, not both",
            )),
            (Some(s), None) => Ok(Some(Self::State(s))),
            (None, a) => Ok(a.map(Self::from)),
        }
    }

    /// The start when a front end is given none: [`Start::Level`] for a log without fixes
    /// (nothing else could give a heading or a position; the frame is then the start's own),
    /// none with fixes (the user chooses between a truth row and the alignments).
    #[must_use]
    pub fn when_not_given(has_fixes: bool) -> Option<Self> {
        (!has_fixes).then_some(Self::Level)
    }
}

impl From<AlignName> for Start<'_> {
    fn from(a: AlignName) -> Self {
        match a {
            AlignName::Gnss => Self::AlignGnss,
            AlignName::Static => Self::AlignStatic {
                duration_s: STATIC_ALIGN_S,
            },
            AlignName::Level => Self::Level,
        }
    }
}

/// A fusion as a front end states it, beside the scenario that gives the filter its model;
/// checked once, in [`FuseRequest::setup`], whose errors name the fields as written here
/// (`initial`, `align`, `earth`, `nhc_sigma_m_s`, `covariance_interval_s`, `rest_s`). Its
/// [`Default`] is every front end's default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuseRequest<'a> {
    /// Where the filter starts: a truth row or an alignment ([`Start::of`] turns a front end's
    /// two options into one).
    pub start: Option<Start<'a>>,
    /// The Earth the user expects; the scenario decides, so a different one is refused.
    pub earth: Option<EarthName>,
    /// The innovation gate ([`FuseSetup::gate`]) on.
    pub gate: bool,
    /// Non-holonomic constraints' one-sigma, m/s (`None`: off).
    pub nhc_sigma_m_s: Option<f64>,
    /// The covariance interval, s (`None`: [`DEFAULT_COVARIANCE_INTERVAL_S`](super::DEFAULT_COVARIANCE_INTERVAL_S)).
    pub covariance_interval_s: Option<f64>,
    /// Estimate the sensor errors (36 states); `None`: when the part warrants it
    /// ([`FuseSetup::warrants_sensor_errors`]).
    pub sensor_errors: Option<bool>,
    /// Seconds at rest at the start (`None`: found in the readings; `Some(0.0)`: no rest).
    pub rest_s: Option<f64>,
    /// Smooth the estimate forward–backward ([`FuseSetup::smooth`]).
    pub smooth: bool,
    /// Zero-velocity updates at stances ([`FuseSetup::zupt`]).
    pub zupt: bool,
    /// Scale the fixes' noise from their innovations, up to
    /// [`DEFAULT_MAX_FIX_NOISE_SCALE`](super::DEFAULT_MAX_FIX_NOISE_SCALE) in variance
    /// ([`FuseSetup::max_fix_noise_scale`]).
    pub adapt_fixes: bool,
}

impl Default for FuseRequest<'_> {
    fn default() -> Self {
        Self {
            start: None,
            earth: None,
            gate: true,
            nhc_sigma_m_s: None,
            covariance_interval_s: None,
            sensor_errors: None,
            rest_s: None,
            smooth: false,
            zupt: false,
            adapt_fixes: false,
        }
    }
}

impl<'a> FuseRequest<'a> {
    /// The filter's setup from `scenario` and this request, and where it starts.
    ///
    /// # Errors
    /// Both starts or neither (field `initial`), an Earth other than the scenario's (field
    /// `earth`), and as [`FuseSetup::from_scenario`].
    pub fn setup(&self, scenario: &crate::Scenario) -> Result<(FuseSetup, Start<'a>)> {
        self.apply(FuseSetup::from_scenario(scenario)?)
    }

    /// This request applied to the filter's model `setup` (from a scenario or a
    /// [`PartModel`](super::PartModel)), and where it starts.
    ///
    /// # Errors
    /// Both starts or neither (field `initial`), an Earth other than the model's (field
    /// `earth`).
    pub fn apply(&self, setup: FuseSetup) -> Result<(FuseSetup, Start<'a>)> {
        let start = self.start()?;
        Ok((self.policy(setup)?, start))
    }

    /// Where the filter starts.
    ///
    /// # Errors
    /// No start (field `initial`).
    pub fn start(&self) -> Result<Start<'a>> {
        self.start.ok_or_else(|| {
            refused(
                RequestOption::Initial,
                "the filter needs a start: the initial state (a truth row) or an alignment: \
                 \"gnss\" (from the first fix at speed), \"static\" (at rest on the WGS-84 \
                 Earth) or \"level\" (at rest, heading zero)",
            )
        })
    }

    /// This request's policy (everything but the start) applied to the filter's model `setup`:
    /// the gate, the constraints, the covariance interval, the sensor-error states, the rest,
    /// smoothing and stances. Every front end (the command line, Python, `study`) sets the
    /// filter up through it, so that the same request gives the same filter.
    ///
    /// # Errors
    /// An Earth other than the model's (field `earth`).
    pub fn policy(&self, mut setup: FuseSetup) -> Result<FuseSetup> {
        let earth = if setup.earth.is_some() {
            EarthName::Wgs84
        } else {
            EarthName::Flat
        };
        if let Some(e) = self.earth
            && e != earth
        {
            return Err(refused(
                RequestOption::Earth,
                format!(
                    "\"{e}\": the filter's model (the scenario's, or the data's) is on the \
                     {earth} Earth"
                ),
            ));
        }
        if !self.gate {
            setup.gate = Gate::Off;
        }
        setup.aiding.nhc_sigma_m_s = self.nhc_sigma_m_s;
        if let Some(s) = self.covariance_interval_s {
            setup.covariance_interval_s = s;
        }
        setup.estimate_sensor_errors = self
            .sensor_errors
            .unwrap_or_else(|| setup.warrants_sensor_errors());
        match self.rest_s {
            Some(s) => {
                setup.rest_s = s;
                setup.detect_rest = false;
            }
            None => setup.detect_rest = true,
        }
        setup.smooth = self.smooth;
        setup.zupt = self.zupt;
        if self.adapt_fixes {
            setup.max_fix_noise_scale = super::DEFAULT_MAX_FIX_NOISE_SCALE;
        }
        Ok(setup)
    }
}
