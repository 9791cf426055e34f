//! The vector kernels of `imu_core::trig` against correctly rounded references (CORE-MATH's
//! functions, through the `pxfm` crate): within `MAX_ULP` on random arguments of every range they
//! take, exact on signed zeros, the library's own answer outside their range, and a value's
//! result independent of where it sits in the slice.
use imu_core::trig::{MAX_ULP, SIN_COS_MAX_ARG, atan2_into, sin_cos_into};

/// `|a − b|` in units in the last place of `b` (a correctly rounded, finite reference).
fn ulps(a: f64, b: f64) -> f64 {
    if a == b {
        return 0.0;
    }
    let ulp = f64::from_bits(b.abs().to_bits() + 1) - b.abs();
    (a - b).abs() / ulp
}

/// `n` uniform numbers in `[−r, r]` (xorshift64, fixed seed).
fn uniform(n: usize, r: f64, mut seed: u64) -> Vec<f64> {
    (0..n)
        .map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            ((seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * r
        })
        .collect()
}

const SAMPLES: usize = 100_000;

#[test]
fn sines_and_cosines_are_within_the_bound_of_the_correctly_rounded_values() {
    for (k, range) in [
        1e-6,
        1.0,
        std::f64::consts::PI,
        100.0,
        1e4,
        1e6,
        SIN_COS_MAX_ARG,
    ]
    .into_iter()
    .enumerate()
    {
        let x = uniform(SAMPLES, range, 0x9E37_79B9 + k as u64);
        let (mut s, mut c) = (vec![0.0; SAMPLES], vec![0.0; SAMPLES]);
        sin_cos_into(&x, &mut s, &mut c);
        let (mut worst_s, mut worst_c) = (0.0_f64, 0.0_f64);
        for i in 0..SAMPLES {
            worst_s = worst_s.max(ulps(s[i], pxfm::f_sin(x[i])));
            worst_c = worst_c.max(ulps(c[i], pxfm::f_cos(x[i])));
        }
        assert!(
            worst_s <= f64::from(MAX_ULP) && worst_c <= f64::from(MAX_ULP),
            "|x| ≤ {range:e}: sin off by {worst_s} ulp, cos by {worst_c}"
        );
    }
}

/// Random arguments of every range the kernel takes, and the places where the quadrant changes:
/// odd multiples of π/4 (where |x|·2/π is a half and ties go to even) and their neighbours,
/// signed zeros, tiny and subnormal numbers, and the largest arguments the kernel takes (a whole
/// number of vectors).
fn quadrant_edges_and_every_range() -> Vec<f64> {
    let mut x: Vec<f64> = [1e-300, 1e-6, 1.0, 10.0, 1e3, 1e5, 1e7, SIN_COS_MAX_ARG]
        .into_iter()
        .enumerate()
        .flat_map(|(k, r)| uniform(20_000, r, 0x51_7CC1 + k as u64))
        .collect();
    for k in -2000_i32..=2000 {
        let at = f64::from(k) * std::f64::consts::FRAC_PI_4;
        let below = f64::from_bits(at.abs().to_bits().saturating_sub(1)).copysign(at);
        let above = f64::from_bits(at.abs().to_bits() + 1).copysign(at);
        x.extend([at, below, above]);
    }
    let largest = f64::from_bits(SIN_COS_MAX_ARG.to_bits() - 1);
    x.extend([
        0.0,
        -0.0,
        f64::MIN_POSITIVE,
        -5e-324,
        5e-324,
        largest,
        -largest,
    ]);
    x.truncate(x.len() - x.len() % 4);
    x
}

// `wide` fuses its multiply-adds where the build has FMA (and on AArch64); the kernel never
// does, so there the two differ within the bound.
#[test]
#[cfg_attr(
    any(target_feature = "fma", target_arch = "aarch64"),
    ignore = "wide fuses its multiply-adds in this build"
)]
fn sines_and_cosines_are_wides_own_bit_for_bit() {
    // The kernel reads the quadrant from the bits of |x|·2/π + 2⁵² instead of calling `wide`'s
    // rounding and conversion; every result must still be `wide::f64x4::sin_cos`'s.
    let x = quadrant_edges_and_every_range();
    let (mut s, mut c) = (vec![0.0; x.len()], vec![0.0; x.len()]);
    sin_cos_into(&x, &mut s, &mut c);
    let mut checked = 0;
    for (k, v) in x.chunks_exact(4).enumerate() {
        let (ws, wc) = wide::f64x4::from([v[0], v[1], v[2], v[3]]).sin_cos();
        let (ws, wc) = (ws.to_array(), wc.to_array());
        for lane in 0..4 {
            let i = 4 * k + lane;
            assert_eq!(
                (s[i].to_bits(), c[i].to_bits()),
                (ws[lane].to_bits(), wc[lane].to_bits()),
                "x = {:e} ({:#x}): ({}, {}) against wide's ({}, {})",
                x[i],
                x[i].to_bits(),
                s[i],
                c[i],
                ws[lane],
                wc[lane]
            );
            checked += 1;
        }
    }
    assert!(checked > 170_000, "{checked}");
}

// The only test in this file that switches the AVX2 copy: the others may run meanwhile and see
// either copy, which give the same numbers (that is what this checks).
#[test]
fn the_avx2_kernel_gives_the_baselines_numbers_bit_for_bit() {
    let x = quadrant_edges_and_every_range();
    let run = |avx2: bool| {
        imu_core::cpu::allow_avx2(avx2);
        let (mut s, mut c) = (vec![0.0; x.len()], vec![0.0; x.len()]);
        sin_cos_into(&x, &mut s, &mut c);
        (s, c)
    };
    let (baseline, avx2) = (run(false), run(true));
    if !imu_core::cpu::avx2_in_use() {
        eprintln!("this CPU runs no AVX2 copy: both runs were the baseline's");
    }
    for (i, &v) in x.iter().enumerate() {
        assert_eq!(
            (avx2.0[i].to_bits(), avx2.1[i].to_bits()),
            (baseline.0[i].to_bits(), baseline.1[i].to_bits()),
            "x = {v:e}: AVX2 ({}, {}), baseline ({}, {})",
            avx2.0[i],
            avx2.1[i],
            baseline.0[i],
            baseline.1[i]
        );
    }
}

#[test]
fn arctangents_are_within_the_bound_of_the_correctly_rounded_values() {
    for (k, (ry, rx)) in [
        (1.0, 1.0),
        (1e-3, 1.0),
        (1.0, 1e-3),
        (1e3, 1e3),
        (1e-200, 1e-200),
    ]
    .into_iter()
    .enumerate()
    {
        let y = uniform(SAMPLES, ry, 0x1234_5678 + k as u64);
        let x = uniform(SAMPLES, rx, 0x8765_4321 + k as u64);
        let mut a = vec![0.0; SAMPLES];
        atan2_into(&y, &x, &mut a);
        let worst = (0..SAMPLES)
            .map(|i| ulps(a[i], pxfm::f_atan2(y[i], x[i])))
            .fold(0.0_f64, f64::max);
        assert!(
            worst <= f64::from(MAX_ULP),
            "|y| ≤ {ry:e}, |x| ≤ {rx:e}: off by {worst} ulp"
        );
    }
}

#[test]
fn signed_zeros_are_exact() {
    let (mut s, mut c) = ([1.0; 2], [0.0; 2]);
    sin_cos_into(&[0.0, -0.0], &mut s, &mut c);
    assert_eq!(
        s.map(f64::to_bits),
        [0.0_f64.to_bits(), (-0.0_f64).to_bits()]
    );
    assert_eq!(c, [1.0, 1.0]);
    let mut a = [1.0; 4];
    atan2_into(&[0.0, -0.0, 0.0, -0.0], &[0.0, 0.0, -0.0, -0.0], &mut a);
    let pi = std::f64::consts::PI;
    assert_eq!(
        a.map(f64::to_bits),
        [0.0, -0.0, pi, -pi].map(f64::to_bits),
        "atan2 of signed zeros"
    );
}

#[test]
fn arguments_outside_the_kernels_range_get_the_library_answer() {
    let x = [
        SIN_COS_MAX_ARG,
        -1e10,
        1e300,
        f64::INFINITY,
        f64::NAN,
        f64::MIN_POSITIVE,
        5e-324,
    ];
    let (mut s, mut c) = ([0.0; 7], [0.0; 7]);
    sin_cos_into(&x, &mut s, &mut c);
    for (i, &xi) in x.iter().enumerate().take(5) {
        let (rs, rc) = xi.sin_cos();
        assert!(
            s[i].to_bits() == rs.to_bits() || (s[i].is_nan() && rs.is_nan()),
            "sin {xi}: {} vs {rs}",
            s[i]
        );
        assert!(
            c[i].to_bits() == rc.to_bits() || (c[i].is_nan() && rc.is_nan()),
            "cos {xi}: {} vs {rc}",
            c[i]
        );
    }
    // Subnormal and tiny arguments: sin x = x, cos x = 1.
    assert_eq!(
        (s[5], c[5], s[6], c[6]),
        (f64::MIN_POSITIVE, 1.0, 5e-324, 1.0)
    );
    let (y, xs) = (
        [1.0, f64::INFINITY, f64::NAN, 2.0],
        [f64::INFINITY, 1.0, 1.0, -f64::INFINITY],
    );
    let mut a = [0.0; 4];
    atan2_into(&y, &xs, &mut a);
    for i in 0..4 {
        let r = y[i].atan2(xs[i]);
        assert!(
            a[i].to_bits() == r.to_bits() || (a[i].is_nan() && r.is_nan()),
            "atan2({}, {})",
            y[i],
            xs[i]
        );
    }
}

#[test]
fn a_value_gets_the_same_result_wherever_it_sits() {
    let x = uniform(103, 50.0, 77);
    let (mut s, mut c) = (vec![0.0; 103], vec![0.0; 103]);
    sin_cos_into(&x, &mut s, &mut c);
    let mut a = vec![0.0; 103];
    atan2_into(&x, &s, &mut a);
    for start in [1, 2, 3, 5, 50] {
        for len in [1, 2, 3, 4, 7, 40] {
            let end = (start + len).min(103);
            let (mut s2, mut c2, mut a2) = (vec![0.0; len], vec![0.0; len], vec![0.0; len]);
            sin_cos_into(&x[start..end], &mut s2, &mut c2);
            atan2_into(&x[start..end], &s[start..end], &mut a2);
            let n = end - start;
            assert_eq!(s2[..n], s[start..end], "sines of {start}..{end}");
            assert_eq!(c2[..n], c[start..end], "cosines of {start}..{end}");
            assert_eq!(a2[..n], a[start..end], "arctangents of {start}..{end}");
        }
    }
}

/// `EulerTrig::of_each` (many attitudes) against the correctly rounded values: the half angles'
/// within `MAX_ULP`, the pitch's and roll's sines within `DOUBLE_ANGLE_ULP` ulp and their
/// cosines within `DOUBLE_ANGLE_ULP` ulp of 1 (the double-angle formulas); zero rolls on the
/// two-value path with exact `(±0, 1)`; split anywhere, the same numbers.
#[test]
fn many_attitudes_trig_is_within_the_bound_of_the_correctly_rounded_values() {
    use imu_core::EulerZyx;
    use imu_core::kinematics::euler::{DOUBLE_ANGLE_ULP, EulerTrig};
    let n = 20_000;
    let yaw = uniform(n, 10.0, 5);
    // Pitch over its whole range, ±π/2 included (the cosine's absolute bound matters there).
    let mut pitch = uniform(n, std::f64::consts::FRAC_PI_2, 6);
    pitch[..4].copy_from_slice(&[
        std::f64::consts::FRAC_PI_2,
        -std::f64::consts::FRAC_PI_2,
        0.0,
        -0.0,
    ]);
    let roll = uniform(n, 3.0, 7);
    let ulp_of_one = f64::EPSILON;
    let (mut worst_sin, mut worst_cos) = (0.0_f64, 0.0_f64);
    for zero_roll in [false, true] {
        let euler: Vec<EulerZyx> = (0..n)
            .map(|i| {
                let r = if zero_roll { 0.0 * roll[i] } else { roll[i] };
                EulerZyx::new(yaw[i], pitch[i], r)
            })
            .collect();
        let mut many = vec![EulerTrig::of(EulerZyx::default()); n];
        EulerTrig::of_each(&euler, &mut many);
        for (e, got) in euler.iter().zip(&many) {
            let halves = [
                (e.yaw_rad * 0.5, got.half.yaw),
                (e.pitch_rad * 0.5, got.half.pitch),
                (e.roll_rad * 0.5, got.half.roll),
            ];
            for (x, (s, c)) in halves {
                assert!(
                    ulps(s, pxfm::f_sin(x)) <= f64::from(MAX_ULP),
                    "{e:?}: sin({x})"
                );
                assert!(
                    ulps(c, pxfm::f_cos(x)) <= f64::from(MAX_ULP),
                    "{e:?}: cos({x})"
                );
            }
            let p = got.pitch_roll;
            for (x, s, c) in [
                (e.pitch_rad, p.sin_pitch, p.cos_pitch),
                (e.roll_rad, p.sin_roll, p.cos_roll),
            ] {
                worst_sin = worst_sin.max(ulps(s, pxfm::f_sin(x)));
                worst_cos = worst_cos.max((c - pxfm::f_cos(x)).abs() / ulp_of_one);
            }
            if zero_roll {
                assert_eq!(p.sin_roll.to_bits(), e.roll_rad.to_bits());
                assert_eq!((p.cos_roll, got.half.roll.1), (1.0, 1.0));
            }
        }
        assert_eq!(many[2].pitch_roll.sin_pitch.to_bits(), 0.0_f64.to_bits());
        assert_eq!(many[3].pitch_roll.sin_pitch.to_bits(), (-0.0_f64).to_bits());
        assert_eq!(many[2].pitch_roll.cos_pitch, 1.0);
        // Split anywhere, the same numbers.
        let mut split = many.clone();
        EulerTrig::of_each(&euler[..37], &mut split[..37]);
        EulerTrig::of_each(&euler[37..], &mut split[37..]);
        assert_eq!(split, many);
    }
    eprintln!("double angles: sin {worst_sin} ulp, cos {worst_cos} ulp of 1");
    let bound = f64::from(DOUBLE_ANGLE_ULP);
    assert!(
        worst_sin <= bound && worst_cos <= bound,
        "sin off by {worst_sin} ulp, cos by {worst_cos} ulp of 1"
    );
}

/// `TangentSample::of_each` (kernels' arctangents, many samples) against `TangentSample::at`
/// (the library's, one): speeds, rates and angular accelerations bit for bit, the angles within
/// `MAX_ULP + 1` ulp; split anywhere, the same numbers.
#[test]
fn many_tangent_samples_are_one_samples_within_the_bound() {
    use imu_core::kinematics::tangent::TangentSample;
    let n = 77;
    let axes = |scale: f64, seed: u64| -> Vec<[f64; 3]> {
        let u = uniform(3 * n, scale, seed);
        u.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
    };
    let (v, a, j) = (axes(20.0, 11), axes(5.0, 12), axes(2.0, 13));
    let mut many = vec![TangentSample::default(); n];
    TangentSample::of_each(&v, &a, &j, &mut many);
    for i in 0..n {
        let (got, want) = (many[i], TangentSample::at(v[i], a[i], j[i]));
        assert_eq!(
            (got.speed_m_s, got.horizontal_m_s),
            (want.speed_m_s, want.horizontal_m_s)
        );
        assert_eq!(
            (got.angles.rate, got.angles.accel),
            (want.angles.rate, want.angles.accel)
        );
        for (g, w) in [
            (got.angles.euler.yaw_rad, want.angles.euler.yaw_rad),
            (got.angles.euler.pitch_rad, want.angles.euler.pitch_rad),
        ] {
            assert!(
                ulps(g, w) <= f64::from(MAX_ULP + 1),
                "sample {i}: {g} vs {w}"
            );
        }
        assert_eq!(got.angles.euler.roll_rad, 0.0);
    }
    let mut split = vec![TangentSample::default(); n];
    TangentSample::of_each(&v[..20], &a[..20], &j[..20], &mut split[..20]);
    TangentSample::of_each(&v[20..], &a[20..], &j[20..], &mut split[20..]);
    assert_eq!(split, many);
}
