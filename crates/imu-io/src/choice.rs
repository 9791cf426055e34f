//! Options chosen by name: the one place where a name becomes a typed choice.
//!
//! A request's options (the navigation frame, the accelerometer sign, the Earth, the scheme,
//! the vertical channel, a filter…) are enums implementing [`Choice`]: the names each takes,
//! its default, and the parse whose refusal names the field and lists the names
//! ([`Error::UnknownChoice`]). The command line builds its flags' accepted values and defaults
//! from the same list, and Python parses its keyword strings with [`Choice::parse`], so the two
//! front ends accept the same names and start from the same defaults.
use crate::error::{Error, Result};

/// An option chosen by name.
pub trait Choice: Copy + PartialEq + Default + core::fmt::Debug + Send + Sync + 'static {
    /// What is chosen, for messages (`"navigation frame"`).
    const WHAT: &'static str;
    /// Every choice with its name, as front ends write it.
    const NAMES: &'static [(&'static str, Self)];

    /// The name of this choice.
    #[must_use]
    fn name(self) -> &'static str {
        Self::NAMES
            .iter()
            .find(|(_, c)| *c == self)
            .map_or("", |(n, _)| *n)
    }

    /// The choice called `text` (any case), else a refusal naming `field` and the names.
    ///
    /// # Errors
    /// [`Error::UnknownChoice`].
    fn parse(field: &str, text: &str) -> Result<Self> {
        Self::NAMES
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(text))
            .map(|(_, c)| *c)
            .ok_or_else(|| Error::UnknownChoice {
                field: field.to_string(),
                what: Self::WHAT,
                value: text.to_string(),
                choices: Self::NAMES.iter().map(|(n, _)| *n).collect(),
            })
    }

    /// The default choice's name (what a front end shows as the default).
    #[must_use]
    fn default_name() -> &'static str {
        Self::default().name()
    }
}

/// Implements [`core::fmt::Display`] as the choice's name.
#[macro_export]
macro_rules! display_as_name {
    ($($t:ty),* $(,)?) => {
        $(impl core::fmt::Display for $t {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str($crate::choice::Choice::name(*self))
            }
        })*
    };
}
pub use display_as_name;

/// The core's planar dead-reckoning schemes by name (the core has no names: it is `no_std`
/// and knows no front end).
impl Choice for imu_core::strapdown::planar::PlanarScheme {
    const WHAT: &'static str = "scheme";
    const NAMES: &'static [(&'static str, Self)] =
        &[("trapezoid", Self::Trapezoid), ("exercise", Self::Exercise)];
}
