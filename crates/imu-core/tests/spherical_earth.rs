//! A third Earth costs one implementation: a non-rotating sphere written here, outside the
//! crate, runs the same strapdown schemes, and its Schuler period is 2π√(R/g).
use imu_core::earth::{EarthModel, EarthTerms, ErrorCouplings};
use imu_core::strapdown::{
    NavState, StrapdownOptions, VerticalChannel, strapdown_increments, strapdown_rates_rk4,
};
use imu_core::{Ned, Vec3};

/// A sphere of radius `R` that does not turn, gravity `g₀ (R/(R + h))²` towards its centre;
/// local NED, coordinates latitude, longitude (rad), height (m).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Sphere {
    radius_m: f64,
    gravity_m_s2: f64,
}

impl Sphere {
    fn rho(&self, c: &[f64; 3]) -> f64 {
        self.radius_m + c[2]
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct LatLonHeight([f64; 3]);

impl EarthModel for Sphere {
    type Frame = Ned;
    type Position = LatLonHeight;
    const ROTATING: bool = true;

    fn coordinates(p: &LatLonHeight) -> [f64; 3] {
        p.0
    }
    fn position(c: [f64; 3]) -> LatLonHeight {
        LatLonHeight(c)
    }
    fn terms(&self, c: &[f64; 3], v: &Vec3<Ned>) -> EarthTerms<Ned> {
        let rho = self.rho(c);
        let g = self.gravity_m_s2 * (self.radius_m / rho).powi(2);
        EarthTerms {
            gravity_m_s2: Vec3::new(0.0, 0.0, g),
            earth_rate_rad_s: Vec3::zeros(),
            transport_rate_rad_s: Vec3::new(v.y() / rho, -v.x() / rho, -v.y() * c[0].tan() / rho),
        }
    }
    fn position_rate(&self, c: &[f64; 3], v: &Vec3<Ned>) -> [f64; 3] {
        let rho = self.rho(c);
        [v.x() / rho, v.y() / (rho * c[0].cos()), -v.z()]
    }
    fn in_domain(&self, c: &[f64; 3]) -> bool {
        c[0].abs() < 89.9f64.to_radians()
    }
    fn height_m(&self, c: &[f64; 3]) -> (f64, f64) {
        (c[2], 1.0)
    }
    fn radius_m(&self, _c: &[f64; 3]) -> f64 {
        self.radius_m
    }
    fn displacement_m(&self, from: &[f64; 3], to: &[f64; 3]) -> Vec3<Ned> {
        let rho = self.rho(from);
        Vec3::new(
            (to[0] - from[0]) * rho,
            (to[1] - from[1]) * rho * from[0].cos(),
            from[2] - to[2],
        )
    }
    fn offset(&self, c: &[f64; 3], d: &Vec3<Ned>) -> [f64; 3] {
        let rho = self.rho(c);
        [
            c[0] + d.x() / rho,
            c[1] + d.y() / (rho * c[0].cos()),
            c[2] - d.z(),
        ]
    }
    fn couplings(&self, c: &[f64; 3], _v: &Vec3<Ned>) -> Option<ErrorCouplings> {
        let rho = self.rho(c);
        let mut gravity_gradient = [[0.0; 3]; 3];
        gravity_gradient[2][2] = 2.0 * self.gravity_m_s2 / rho;
        let mut rate_by_velocity = [[0.0; 3]; 3];
        rate_by_velocity[0][1] = 1.0 / rho;
        rate_by_velocity[1][0] = -1.0 / rho;
        rate_by_velocity[2][1] = -c[0].tan() / rho;
        Some(ErrorCouplings {
            gravity_gradient,
            rate_by_position: [[0.0; 3]; 3],
            rate_by_velocity,
        })
    }
}

const SPHERE: Sphere = Sphere {
    radius_m: 6_371_000.0,
    gravity_m_s2: 9.8,
};

/// The times at which the north velocity crosses zero (linear interpolation).
fn zero_crossings(states: &[NavState<Sphere>]) -> Vec<f64> {
    states
        .windows(2)
        .filter_map(|w| {
            let (a, b) = (w[0].velocity_m_s.x(), w[1].velocity_m_s.x());
            (a.signum() != b.signum() && a != 0.0)
                .then(|| w[0].t_s + (w[1].t_s - w[0].t_s) * a / (a - b))
        })
        .collect()
}

/// A body at rest on the sphere, its navigation started with 0.1 m/s north: the velocity error
/// oscillates at the Schuler frequency √(g/R).
fn schuler_period(rk4: bool) -> f64 {
    let rate_hz = 5.0;
    let n = (2.2 * 5066.0 * rate_hz) as usize;
    let t: Vec<f64> = (0..n).map(|k| k as f64 / rate_hz).collect();
    // FRD at rest, level: the accelerometer reads −g on its down axis.
    let f = vec![[0.0, 0.0, -SPHERE.gravity_m_s2]; n];
    let w = vec![[0.0; 3]; n];
    let start = NavState::<Sphere> {
        velocity_m_s: Vec3::new(0.1, 0.0, 0.0),
        position: LatLonHeight([0.5, 0.2, 0.0]),
        ..NavState::default()
    };
    let options = StrapdownOptions {
        vertical: VerticalChannel::Hold,
        ..StrapdownOptions::default()
    };
    let mut out = vec![NavState::<Sphere>::default(); n];
    if rk4 {
        strapdown_rates_rk4(SPHERE, &t, &w, &f, None, start, options, 1, &mut out).unwrap();
    } else {
        let dt = 1.0 / rate_hz;
        let dth = vec![[0.0; 3]; n];
        let dv: Vec<[f64; 3]> = f.iter().map(|a| a.map(|x| x * dt)).collect();
        strapdown_increments(SPHERE, &t, &dth, &dv, None, start, options, &mut out).unwrap();
    }
    let z = zero_crossings(&out);
    assert!(z.len() >= 4, "{z:?}");
    // Crossings half a period apart: the period from the first to the fourth.
    (z[3] - z[0]) / 1.5
}

#[test]
fn the_schuler_period_on_a_sphere_is_two_pi_root_r_over_g() {
    let expected = 2.0 * std::f64::consts::PI * (SPHERE.radius_m / SPHERE.gravity_m_s2).sqrt();
    for rk4 in [true, false] {
        let period = schuler_period(rk4);
        let relative = (period / expected - 1.0).abs();
        assert!(
            relative < 1e-3,
            "rk4 {rk4}: period {period} s against 2π√(R/g) = {expected} s ({relative:e})"
        );
    }
}
