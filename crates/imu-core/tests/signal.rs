//! The signal chain against closed forms: a Butterworth's −3 dB point, a sine aliased by the
//! decimation with the filter's gain and phase, the delay of a ramp equal to the group delay,
//! an average's zeros and delay, white noise shaped by |H|² (Parseval), and the refusals.
use core::f64::consts::PI;

use imu_core::sensor::{NoiseSource, SeededNormals};
use imu_core::signal::{Chain, ChainState, LowPass, SignalError};

/// Runs `x(t)` through `chain` from a settled start at `x(0)` for `seconds`: the output times
/// and the x axis's outputs.
fn run(chain: &Chain, x: impl Fn(f64) -> f64, seconds: f64) -> (Vec<f64>, Vec<f64>) {
    let fs = chain.internal_rate_hz();
    let mut state = ChainState::settled(chain, [x(0.0); 3]);
    let (mut t_out, mut y_out) = (Vec::new(), Vec::new());
    let n = (seconds * fs) as usize;
    for i in 0..n {
        let t = i as f64 / fs;
        if let Some(y) = chain.push(&mut state, [x(t); 3]) {
            t_out.push(t);
            y_out.push(y[0]);
        }
    }
    (t_out, y_out)
}

/// Least-squares amplitude and phase of `y ≈ A·sin(2πft + φ)` at the times `t`.
fn sine_fit(t: &[f64], y: &[f64], f: f64) -> (f64, f64) {
    let (mut ss, mut sc, mut cc, mut ys, mut yc) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (&ti, &yi) in t.iter().zip(y) {
        let (s, c) = (2.0 * PI * f * ti).sin_cos();
        ss += s * s;
        sc += s * c;
        cc += c * c;
        ys += yi * s;
        yc += yi * c;
    }
    let det = ss * cc - sc * sc;
    let (a, b) = ((ys * cc - yc * sc) / det, (yc * ss - ys * sc) / det);
    (a.hypot(b), b.atan2(a))
}

#[test]
fn a_butterworth_passes_zero_frequency_whole_and_its_cutoff_at_one_over_root_two() {
    for order in 1..=8 {
        let chain: Chain = Chain::new(
            1000.0,
            100.0,
            &LowPass::Butterworth {
                order,
                cutoff_hz: 42.0,
            },
        )
        .unwrap();
        assert!((chain.dc_gain() - 1.0).abs() < 1e-12, "order {order}");
        let at_cutoff = chain.response(42.0).gain;
        assert!(
            (at_cutoff - 0.5_f64.sqrt()).abs() < 1e-12,
            "order {order}: {at_cutoff}"
        );
        // Maximally flat: the gain falls with frequency, faster for higher orders.
        let g: Vec<f64> = [10.0, 42.0, 100.0, 400.0]
            .iter()
            .map(|&f| chain.response(f).gain)
            .collect();
        assert!(g.windows(2).all(|w| w[1] < w[0]), "order {order}: {g:?}");
        assert_eq!(chain.sections().len(), order.div_ceil(2));
    }
}

#[test]
fn a_sine_above_the_output_nyquist_appears_at_its_alias_with_the_filters_gain_and_phase() {
    // An internal 8 kHz, a second-order low-pass at 200 Hz, every 80th sample kept (100 Hz).
    let chain: Chain = Chain::new(
        8000.0,
        100.0,
        &LowPass::Butterworth {
            order: 2,
            cutoff_hz: 200.0,
        },
    )
    .unwrap();
    assert_eq!(chain.decimation(), 80);
    for f in [1130.0, 970.0, 3010.0] {
        let (t, y) = run(&chain, |t| (2.0 * PI * f * t).sin(), 3.0);
        // The start's transient has died down after 0.5 s (the poles' time constant is ~1 ms).
        let keep = t.iter().position(|&ti| ti >= 0.5).unwrap();
        let (amplitude, phase) = sine_fit(&t[keep..], &y[keep..], f);
        let h = chain.response(f);
        assert!(
            (amplitude / h.gain - 1.0).abs() < 1e-6,
            "{f} Hz: {amplitude} vs {}",
            h.gain
        );
        assert!(
            (phase - h.phase_rad).abs() < 1e-6,
            "{f} Hz: {phase} vs {}",
            h.phase_rad
        );
        // What the output shows is a sine at the alias frequency, below 50 Hz.
        let alias = chain.alias_hz(f);
        assert!(alias <= 50.0);
        let (a_alias, _) = sine_fit(&t[keep..], &y[keep..], alias);
        assert!(
            (a_alias / h.gain - 1.0).abs() < 1e-6,
            "{f} Hz → {alias} Hz: {a_alias}"
        );
    }
    assert_eq!(chain.alias_hz(1130.0), 30.0);
    assert_eq!(chain.alias_hz(970.0), 30.0);
    assert_eq!(chain.alias_hz(3010.0), 10.0);
}

#[test]
fn a_sine_below_the_output_nyquist_passes_with_the_filters_gain_and_phase() {
    let chain: Chain = Chain::new(
        2000.0,
        200.0,
        &LowPass::Butterworth {
            order: 3,
            cutoff_hz: 60.0,
        },
    )
    .unwrap();
    for f in [5.0, 30.0, 60.0, 90.0] {
        let (t, y) = run(&chain, |t| (2.0 * PI * f * t).sin(), 4.0);
        let keep = t.iter().position(|&ti| ti >= 1.0).unwrap();
        let (amplitude, phase) = sine_fit(&t[keep..], &y[keep..], f);
        let h = chain.response(f);
        assert!((amplitude / h.gain - 1.0).abs() < 1e-6, "{f} Hz");
        assert!((phase - h.phase_rad).abs() < 1e-6, "{f} Hz");
    }
}

#[test]
fn a_ramp_comes_out_late_by_the_group_delay() {
    // A filter of unit gain at zero frequency turns r·t into r·(t − τ(0)) once settled.
    let designs = [
        LowPass::Butterworth {
            order: 1,
            cutoff_hz: 20.0,
        },
        LowPass::Butterworth {
            order: 4,
            cutoff_hz: 50.0,
        },
        LowPass::MovingAverage { taps: 8 },
        LowPass::Bartlett { taps: 4 },
    ];
    for design in designs {
        let chain: Chain = Chain::new(1000.0, 100.0, &design).unwrap();
        let tau = chain.group_delay_s(0.0);
        let (t, y) = run(&chain, |t| 3.0 * t, 2.0);
        let keep = t.iter().position(|&ti| ti >= 1.0).unwrap();
        for (ti, yi) in t[keep..].iter().zip(&y[keep..]) {
            assert!(
                (yi - 3.0 * (ti - tau)).abs() < 1e-9,
                "{design:?}: {yi} vs {}",
                3.0 * (ti - tau)
            );
        }
    }
    // An average of N samples is (N − 1)/2 samples late, a Bartlett of N twice that.
    let fs = 1000.0;
    let average: Chain = Chain::new(fs, 100.0, &LowPass::MovingAverage { taps: 8 }).unwrap();
    assert!((average.group_delay_s(0.0) - 3.5 / fs).abs() < 1e-15);
    assert!(
        (average.group_delay_s(37.0) - 3.5 / fs).abs() < 1e-12,
        "linear phase"
    );
    let bartlett: Chain = Chain::new(fs, 100.0, &LowPass::Bartlett { taps: 4 }).unwrap();
    assert!((bartlett.group_delay_s(0.0) - 3.0 / fs).abs() < 1e-15);
    // A first-order low-pass's delay at zero frequency: 1/(2π f_c) in the analogue limit.
    let slow: Chain = Chain::new(
        100_000.0,
        100.0,
        &LowPass::Butterworth {
            order: 1,
            cutoff_hz: 10.0,
        },
    )
    .unwrap();
    assert!((slow.group_delay_s(0.0) * 2.0 * PI * 10.0 - 1.0).abs() < 1e-6);
}

#[test]
fn an_average_has_its_zeros_at_multiples_of_the_rate_over_its_length() {
    let chain: Chain = Chain::new(800.0, 100.0, &LowPass::MovingAverage { taps: 8 }).unwrap();
    for k in 1..4 {
        assert!(chain.response(100.0 * f64::from(k)).gain < 1e-14);
    }
    // Between them, |sin(πfN/fs) / (N sin(πf/fs))|.
    let f = 130.0;
    let closed = ((PI * f * 8.0 / 800.0).sin() / (8.0 * (PI * f / 800.0).sin())).abs();
    assert!((chain.response(f).gain - closed).abs() < 1e-14);
}

#[test]
fn a_settled_chain_passes_a_constant_from_its_first_sample() {
    let designs = [
        LowPass::None,
        LowPass::Butterworth {
            order: 5,
            cutoff_hz: 30.0,
        },
        LowPass::Bartlett { taps: 3 },
        LowPass::Rational {
            numerator: &[0.2],
            denominator: &[1.0, -0.8],
        },
        LowPass::Fir {
            coefficients: &[0.25, 0.5, 0.25],
        },
    ];
    for design in designs {
        let chain: Chain = Chain::new(400.0, 100.0, &design).unwrap();
        let x = [1.5, -2.0, 9.81];
        let mut state = ChainState::settled(&chain, x);
        let g = chain.dc_gain();
        let mut kept = 0;
        for _ in 0..40 {
            if let Some(y) = chain.push(&mut state, x) {
                kept += 1;
                for k in 0..3 {
                    assert!((y[k] - g * x[k]).abs() < 1e-12, "{design:?}: {y:?}");
                }
            }
        }
        assert_eq!(kept, 10, "every 4th of 40");
    }
}

#[test]
fn white_noise_comes_out_with_the_power_its_response_lets_through() {
    // Output variance σ²·Σh² (the impulse response's energy) equals σ²·∫|H|² df / fs (Parseval);
    // measured on 400 000 samples its relative standard error is about √(2/n_eff).
    let fs = 1000.0;
    let chain: Chain = Chain::new(
        fs,
        fs,
        &LowPass::Butterworth {
            order: 2,
            cutoff_hz: 50.0,
        },
    )
    .unwrap();
    let steps = 20_000;
    let parseval: f64 = (0..steps)
        .map(|i| {
            let f = (i as f64 + 0.5) / steps as f64 * fs - fs / 2.0;
            chain.response(f).gain.powi(2)
        })
        .sum::<f64>()
        / steps as f64;
    let mut impulse = ChainState::settled(&chain, [0.0; 3]);
    let energy: f64 = (0..5000)
        .map(|i| {
            chain
                .push(&mut impulse, [if i == 0 { 1.0 } else { 0.0 }; 3])
                .unwrap()[0]
                .powi(2)
        })
        .sum();
    assert!(
        (energy / parseval - 1.0).abs() < 1e-9,
        "{energy} vs {parseval}"
    );
    let mut noise = SeededNormals::new(7);
    let mut state = ChainState::settled(&chain, [0.0; 3]);
    let n = 400_000;
    let mut sum2 = [0.0; 3];
    for _ in 0..n {
        let x = [0; 3].map(|_| noise.standard_normal());
        let y = chain.push(&mut state, x).unwrap();
        for k in 0..3 {
            sum2[k] += y[k] * y[k];
        }
    }
    // The output is correlated over about fs/(2·50 Hz) = 10 samples: n_eff ≈ n/10.
    let tolerance = 4.0 * (2.0 / (n as f64 / 10.0)).sqrt();
    for s in sum2 {
        let ratio = s / n as f64 / energy;
        assert!(
            (ratio - 1.0).abs() < tolerance,
            "{ratio} (tolerance {tolerance})"
        );
    }
}

#[test]
fn a_chain_it_cannot_be_is_refused_with_what_is_wrong() {
    let make = |fi: f64, fo: f64, lp: LowPass<'_>| {
        Chain::<imu_core::sensor::InlineBuffer>::new(fi, fo, &lp).unwrap_err()
    };
    assert!(matches!(
        make(1000.0, 300.0, LowPass::None),
        SignalError::NotWholeMultiple { .. }
    ));
    assert!(matches!(
        make(100.0, 1000.0, LowPass::None),
        SignalError::NotWholeMultiple { .. }
    ));
    assert!(matches!(
        make(f64::NAN, 100.0, LowPass::None),
        SignalError::NotPositive {
            field: "internal_rate_hz",
            ..
        }
    ));
    assert!(matches!(
        make(
            1000.0,
            100.0,
            LowPass::Butterworth {
                order: 2,
                cutoff_hz: 500.0
            }
        ),
        SignalError::CutoffAboveNyquist { .. }
    ));
    assert!(matches!(
        make(
            1000.0,
            100.0,
            LowPass::Butterworth {
                order: 9,
                cutoff_hz: 50.0
            }
        ),
        SignalError::BadLength {
            field: "order",
            value: 9,
            max: 8
        }
    ));
    // The core's inline storage holds 8 coefficients; a heap buffer holds more.
    let e = make(1000.0, 100.0, LowPass::MovingAverage { taps: 10 });
    assert!(matches!(
        e,
        SignalError::BadLength {
            field: "taps",
            value: 10,
            max: 8
        }
    ));
    assert_eq!(e.to_string(), "taps must be from 1 to 8, got 10");
    assert!(matches!(
        make(
            1000.0,
            100.0,
            LowPass::Fir {
                coefficients: &[0.5, -0.5]
            }
        ),
        SignalError::BadCoefficients { .. }
    ));
    assert!(matches!(
        make(
            1000.0,
            100.0,
            LowPass::Rational {
                numerator: &[1.0],
                denominator: &[0.0, 1.0]
            }
        ),
        SignalError::BadCoefficients { .. }
    ));
    assert!(matches!(
        make(
            1000.0,
            100.0,
            LowPass::Fir {
                coefficients: &[f64::INFINITY]
            }
        ),
        SignalError::BadCoefficients { .. }
    ));
}

#[test]
fn a_data_sheets_bandwidth_and_delay_are_the_filters_own() {
    // The MPU-6050's DLPF_CFG rows (bandwidth Hz, delay s, internal rate Hz): the gyroscope's
    // 256 Hz at 8 kHz, the rest at 1 kHz, from no delay to 19 ms.
    let rows = [
        (260.0, 0.0, 1000.0),
        (256.0, 0.98e-3, 8000.0),
        (184.0, 2.0e-3, 1000.0),
        (94.0, 3.0e-3, 1000.0),
        (44.0, 4.9e-3, 1000.0),
        (21.0, 8.5e-3, 1000.0),
        (10.0, 13.8e-3, 1000.0),
        (5.0, 19.0e-3, 1000.0),
    ];
    for (bandwidth_hz, delay_s, fs) in rows {
        let design = LowPass::BandwidthDelay {
            bandwidth_hz,
            delay_s,
        };
        let chain: Chain = Chain::new(fs, 100.0, &design).unwrap();
        assert!((chain.dc_gain() - 1.0).abs() < 1e-12);
        let gain = chain.response(bandwidth_hz).gain;
        assert!(
            (gain - core::f64::consts::FRAC_1_SQRT_2).abs() < 1e-9,
            "{bandwidth_hz} Hz: gain {gain}"
        );
        assert!(
            (chain.group_delay_s(0.0) - delay_s).abs() < 1e-12,
            "{bandwidth_hz} Hz: delay {} s",
            chain.group_delay_s(0.0)
        );
        // In time: a ramp comes out late by the delay.
        let (t, y) = run(&chain, |t| 3.0 * t, 2.0);
        let keep = t.iter().position(|&ti| ti >= 1.5).unwrap();
        for (ti, yi) in t[keep..].iter().zip(&y[keep..]) {
            assert!(
                (yi - 3.0 * (ti - delay_s)).abs() < 1e-9,
                "{bandwidth_hz} Hz"
            );
        }
        // A low-pass: nothing at half the internal rate (the bilinear transform's zero there),
        // and nowhere more than 1.3 (the zero lifts the no-delay row's response below its
        // bandwidth by up to 27 %).
        assert!(chain.response(fs / 2.0).gain < 1e-9, "{bandwidth_hz} Hz");
        let peak = (0..=500)
            .map(|i| chain.response(fs / 2.0 * f64::from(i) / 500.0).gain)
            .fold(0.0, f64::max);
        assert!(peak < 1.3, "{bandwidth_hz} Hz: peak {peak}");
    }
    let refused = |bandwidth_hz: f64, delay_s: f64| {
        Chain::<imu_core::signal::InlineBuffer>::new(
            1000.0,
            100.0,
            &LowPass::BandwidthDelay {
                bandwidth_hz,
                delay_s,
            },
        )
        .unwrap_err()
    };
    assert!(matches!(
        refused(500.0, 0.0),
        SignalError::CutoffAboveNyquist { .. }
    ));
    assert!(matches!(refused(0.0, 0.0), SignalError::NotPositive { .. }));
    assert!(matches!(
        refused(50.0, -1e-3),
        SignalError::BadCoefficients { .. }
    ));
    assert!(matches!(
        refused(50.0, f64::NAN),
        SignalError::BadCoefficients { .. }
    ));
}
