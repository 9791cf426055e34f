//! Planar dead reckoning: the exercise's rules on a hand-computed case, the default scheme's
//! accuracy and order on a circle, and the exercise's mirrored turns.
use imu_core::strapdown::planar::{
    PlanarError, PlanarSample, PlanarScheme, PlanarState, PlanarStepper, dead_reckon,
};

fn sample(t: f64, ax: f64, ay: f64, w: f64) -> PlanarSample {
    PlanarSample {
        t_s: t,
        accel_x_m_s2: ax,
        accel_y_m_s2: ay,
        gyro_z_rad_s: w,
    }
}

#[test]
fn exercise_scheme_reproduces_its_update_rules_on_three_samples() {
    let s = [
        sample(0.0, 0.0, 0.0, 0.0),
        sample(1.0, 1.0, 0.5, 0.1),
        sample(2.0, 1.0, 0.2, 0.2),
    ];
    let mut out = [PlanarState::default(); 3];
    dead_reckon(
        &s,
        PlanarScheme::Exercise,
        PlanarState::exercise_start(0.0),
        &mut out,
    )
    .unwrap();
    assert_eq!(out[0].position_m, [100.0, 100.0]);
    // Sample 1 by hand: vx = 1, ΔX = 1.5, a_y,clean = 0.5 − 0.1·1 = 0.4, vy = 0.4, ΔY = 0.6, α = 0.1.
    let (x1, y1) = (
        100.0 + 0.1f64.cos() * 1.5 + 0.1f64.sin() * 0.6,
        100.0 - 0.1f64.sin() * 1.5 + 0.1f64.cos() * 0.6,
    );
    // Sample 2: vx = 2, ΔX = 2.5, a_y,clean = 0.2 − 0.2·2 = −0.2, vy = 0.2, ΔY = 0.1, α = 0.3.
    let (x2, y2) = (
        x1 + 0.3f64.cos() * 2.5 + 0.3f64.sin() * 0.1,
        y1 - 0.3f64.sin() * 2.5 + 0.3f64.cos() * 0.1,
    );
    let close = |a: f64, b: f64| (a - b).abs() < 1e-13;
    assert!(
        close(out[1].position_m[0], x1) && close(out[1].position_m[1], y1),
        "{:?}",
        out[1]
    );
    assert!(
        close(out[2].position_m[0], x2) && close(out[2].position_m[1], y2),
        "{:?}",
        out[2]
    );
    assert!(close(out[2].heading_rad, 0.3));
    assert_eq!(out[2].velocity_body_m_s, [2.0, 0.2]);
}

/// Counter-clockwise circle of radius `r` at speed `v`, starting at the origin heading +X.
fn circle(rate_hz: f64, seconds: f64, r: f64, v: f64) -> Vec<PlanarSample> {
    let n = (seconds * rate_hz).round() as usize;
    (0..=n)
        .map(|k| sample(k as f64 / rate_hz, 0.0, v * v / r, v / r))
        .collect()
}

fn truth_at(t: f64, r: f64, v: f64) -> [f64; 2] {
    let a = v * t / r;
    [r * a.sin(), r * (1.0 - a.cos())]
}

fn final_error(rate_hz: f64) -> f64 {
    let (r, v, secs) = (5.0, 2.0, 20.0);
    let s = circle(rate_hz, secs, r, v);
    let start = PlanarState {
        velocity_nav_m_s: [v, 0.0],
        ..PlanarState::default()
    };
    let mut out = vec![PlanarState::default(); s.len()];
    dead_reckon(&s, PlanarScheme::Trapezoid, start, &mut out).unwrap();
    let last = out.last().unwrap();
    let p = truth_at(last.t_s, r, v);
    ((last.position_m[0] - p[0]).powi(2) + (last.position_m[1] - p[1]).powi(2)).sqrt()
}

#[test]
fn default_scheme_follows_a_circle_and_converges_at_second_order() {
    let e = [final_error(50.0), final_error(100.0), final_error(200.0)];
    assert!(e[2] < 1e-3, "{e:?}");
    for k in 0..2 {
        let order = (e[k] / e[k + 1]).log2();
        assert!((order - 2.0).abs() < 0.2, "observed order {order} ({e:?})");
    }
}

#[test]
fn exercise_scheme_mirrors_a_left_turn_into_a_right_turn() {
    let (r, v) = (5.0, 2.0);
    let s = circle(100.0, 2.0, r, v);
    let mut out = vec![PlanarState::default(); s.len()];
    // Start at speed so both schemes see the same motion.
    let start = PlanarState {
        velocity_body_m_s: [v, 0.0],
        velocity_nav_m_s: [v, 0.0],
        ..PlanarState::default()
    };
    dead_reckon(&s, PlanarScheme::Exercise, start, &mut out).unwrap();
    let y_exercise = out.last().unwrap().position_m[1];
    dead_reckon(&s, PlanarScheme::Trapezoid, start, &mut out).unwrap();
    let y_default = out.last().unwrap().position_m[1];
    assert!(y_default > 0.5, "a left turn goes to +Y: {y_default}");
    assert!(
        y_exercise < -0.5,
        "the exercise's R(−α) mirrors it to −Y: {y_exercise}"
    );
    assert!(
        (y_exercise + y_default).abs() < 0.05 * y_default,
        "{y_exercise} vs {y_default}"
    );
}

#[test]
fn bad_samples_are_refused_with_their_index() {
    let mut st = PlanarStepper::new(PlanarScheme::Trapezoid, PlanarState::default());
    st.step(&sample(0.0, 0.0, 0.0, 0.0)).unwrap();
    assert_eq!(
        st.step(&sample(0.0, 0.0, 0.0, 0.0)),
        Err(PlanarError::TimeNotIncreasing { index: 1 })
    );
    assert_eq!(
        st.step(&sample(0.1, f64::NAN, 0.0, 0.0)),
        Err(PlanarError::NotFinite { index: 1 })
    );
    let mut out = [PlanarState::default(); 1];
    assert_eq!(
        dead_reckon(
            &[sample(0.0, 0.0, 0.0, 0.0); 2],
            PlanarScheme::Exercise,
            PlanarState::default(),
            &mut out
        ),
        Err(PlanarError::OutputTooShort { needed: 2 })
    );
}
