//! A streamed simulation equals the whole one bit for bit, chunk by chunk and gathered into
//! tables, on one thread and on two (the truth a chunk ahead): every trajectory type, rates and
//! increments, a Monte Carlo run, chunk boundaries inside a tangent-attitude standstill, the
//! aids' readings, the WGS-84 Earth.
use std::path::Path;

use imukit::run::pipeline::RunThreads;
use imukit::run::simulate::STREAM_CHUNK;
use imukit::scenario::builtin;
use imukit::{Scenario, ScenarioSpec};

fn streamed(sc: &Scenario, run: Option<u64>, threads: RunThreads) -> (Vec<f64>, Vec<f64>, usize) {
    let (mut truth, mut imu, mut chunks) = (Vec::new(), Vec::new(), 0);
    sc.stream(run, threads, |c| {
        assert!(c.truth.columns.len() * STREAM_CHUNK >= c.truth.data.len() || chunks == 0);
        truth.extend_from_slice(&c.truth.data);
        imu.extend_from_slice(&c.imu.data);
        chunks += 1;
        Ok(())
    })
    .unwrap();
    (truth, imu, chunks)
}

fn assert_same(sc: &Scenario, run: Option<u64>, min_chunks: usize, what: &str) {
    let whole = match run {
        Some(r) => sc.simulate_run(r).unwrap(),
        None => sc.simulate().unwrap(),
    };
    for threads in [RunThreads::One, RunThreads::Two] {
        let (truth, imu, chunks) = streamed(sc, run, threads);
        assert!(chunks >= min_chunks, "{what} {threads:?}: {chunks} chunks");
        assert!(
            truth == whole.truth.data,
            "{what} {threads:?}: truth differs"
        );
        assert!(
            imu == whole.imu.data,
            "{what} {threads:?}: IMU readings differ"
        );
        // The streamed chunks gathered into tables (what Python's simulate returns): every
        // table.
        let gathered = sc.simulate_streamed(run, threads).unwrap();
        assert!(
            gathered == whole,
            "{what} {threads:?}: the gathered tables differ"
        );
    }
}

fn builtin_at(name: &str, rate_hz: f64, duration_s: f64, imu: &str) -> Scenario {
    let mut text = builtin::toml(name).unwrap();
    text = text
        .lines()
        .filter(|l| !l.starts_with("rate_hz") && !l.starts_with("duration_s"))
        .collect::<Vec<_>>()
        .join("\n");
    let text = format!("rate_hz = {rate_hz}\nduration_s = {duration_s}\n{text}\n{imu}");
    ScenarioSpec::from_toml(&text, name)
        .unwrap()
        .resolve(Path::new("."))
        .unwrap()
}

#[test]
fn analytic_trajectories_stream_to_the_same_numbers() {
    let noisy = "";
    for name in [
        "figure8",
        "tilted-circle",
        "rounded-rectangle",
        "platform-turn",
    ] {
        let sc = builtin_at(name, 1000.0, 10.0, noisy);
        assert_same(&sc, None, 3, name);
    }
}

fn from_toml(text: &str) -> Scenario {
    ScenarioSpec::from_toml(text, "test")
        .unwrap()
        .resolve(Path::new("."))
        .unwrap()
}

#[test]
fn a_standstill_longer_than_a_chunk_is_backfilled_as_in_one_piece() {
    // At rest for 3 s (6000 samples at 2 kHz, more than a chunk), then off along a curve: the
    // tangent attitude of the standstill is the first moving sample's.
    let sc = from_toml(
        "rate_hz = 2000.0\nduration_s = 8.0\n[trajectory]\ntype = \"expression\"\n\
         position_m = [\"if(t < 3, 0, (t - 3)^3)\", \"if(t < 3, 0, (t - 3)^4)\", \"0\"]\n\
         attitude = \"tangent\"\n",
    );
    let whole = sc.simulate().unwrap();
    let yaw = whole.truth.column("yaw_rad").unwrap();
    assert!(
        yaw[0] == yaw[5999] && yaw[0] == yaw[6001],
        "the standstill takes the first moving yaw"
    );
    assert_same(&sc, None, 3, "standstill");
}

#[test]
fn noisy_increments_and_monte_carlo_runs_continue_across_chunks() {
    let sc = from_toml(
        "rate_hz = 500.0\nduration_s = 30.0\n[trajectory]\ntype = \"expression\"\n\
         position_m = [\"cos(t)\", \"sin(t)\", \"0.1*t\"]\nattitude = \"tangent\"\n\
         [imu]\npreset = \"mpu-6050\"\nseed = 5\noutput = \"increments\"\n",
    );
    assert_same(&sc, None, 3, "increments");
    assert_same(&sc, Some(3), 3, "run 3");
}

#[test]
fn example_files_stream_to_the_same_numbers() {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    for f in [
        "samples.toml",
        "body_rates.toml",
        "waypoints.toml",
        "track.toml",
        "expression.toml",
        "piecewise.toml",
        "car_tunnel.toml",
        "earth_flight.toml",
    ] {
        let sc = Scenario::from_file(&examples.join(f)).unwrap();
        assert_same(&sc, None, 1, f);
    }
}

#[test]
fn gathering_into_the_callers_memory_checks_the_shape_first() {
    let sc = builtin_at("figure8", 50.0, 3.0, "");
    let shape = sc.gathered_shape().unwrap();
    assert_eq!(shape.rows, 151);
    assert_eq!(shape.imu_columns.len(), 10, "{:?}", shape.imu_columns);
    assert_eq!(shape.truth_columns.len(), 23);
    let (mut truth, mut imu) = (vec![0.0; 151 * 23], vec![0.0; 151 * 10 - 1]);
    match sc.simulate_streamed_into(None, RunThreads::Two, Some(&mut truth), &mut imu) {
        Err(imukit::Error::Invalid { field, message }) => {
            assert_eq!(field.to_string(), "imu");
            assert!(
                message.contains("1509 values, expected 151 rows × 10"),
                "{message}"
            );
        }
        other => panic!("a short IMU buffer was taken: {other:?}"),
    }
    assert!(
        truth.iter().all(|v| *v == 0.0),
        "written before the shape was checked"
    );
    let mut imu = vec![0.0; 151 * 10];
    sc.simulate_streamed_into(None, RunThreads::Two, Some(&mut truth), &mut imu)
        .unwrap();
    let whole = sc.simulate().unwrap();
    assert!(truth == whole.truth.data && imu == whole.imu.data);
}

#[test]
fn a_short_run_streams_in_smaller_chunks_with_the_same_numbers() {
    use imukit::run::simulate::{MIN_STREAM_CHUNK, stream_chunk};
    assert_eq!(stream_chunk(100), MIN_STREAM_CHUNK);
    assert_eq!(stream_chunk(10_000), 1250);
    assert_eq!(stream_chunk(10_000_000), STREAM_CHUNK);
    // 10 000 noisy samples: eight chunks of 1 250, the same numbers as the whole run on one
    // thread or two (and the chunks are that long).
    let noisy = "[imu.accelerometer]\nNoiseDensity = 0.01\nRandomWalk = 1e-3\n\
                 [imu.gyroscope]\nNoiseDensity = 0.001\nBiasInstability = 1e-4";
    let sc = builtin_at("figure8", 1000.0, 9.999, noisy);
    assert_eq!(sc.t_s.len(), 10_000);
    let whole = sc.simulate_run(4).unwrap();
    for threads in [RunThreads::One, RunThreads::Two] {
        let mut lengths = Vec::new();
        let mut imu = Vec::new();
        sc.stream(Some(4), threads, |c| {
            lengths.push(c.imu.rows());
            imu.extend_from_slice(&c.imu.data);
            Ok(())
        })
        .unwrap();
        assert_eq!(lengths, vec![1250; 8], "{threads:?}");
        assert!(imu == whole.imu.data, "{threads:?}: the readings differ");
    }
}

#[test]
fn readings_alone_are_the_readings_of_a_run_with_its_truth() {
    let noisy = "[imu.accelerometer]\nNoiseDensity = 0.01\nBiasInstability = 0.002\n\
                 [imu.gyroscope]\nNoiseDensity = 0.001\nRandomWalk = 1e-4";
    let figure8 = builtin_at("figure8", 400.0, 25.0, noisy);
    let flight = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/earth_flight.toml");
    for (sc, what) in [
        (figure8, "the figure-8"),
        (Scenario::from_file(&flight).unwrap(), "the WGS-84 flight"),
    ] {
        let shape = sc.gathered_shape().unwrap();
        assert!(shape.rows > 2 * STREAM_CHUNK, "{what}: {} rows", shape.rows);
        let width = shape.imu_columns.len();
        let mut truth = vec![0.0; shape.rows * shape.truth_columns.len()];
        let mut with = vec![0.0; shape.rows * width];
        let mut alone = vec![f64::NAN; shape.rows * width];
        sc.simulate_streamed_into(Some(3), RunThreads::Two, Some(&mut truth), &mut with)
            .unwrap();
        sc.simulate_streamed_into(Some(3), RunThreads::One, None, &mut alone)
            .unwrap();
        assert!(
            with.iter()
                .zip(&alone)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{what}: the readings changed without the truth"
        );
    }
}
