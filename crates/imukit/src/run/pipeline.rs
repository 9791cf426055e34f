//! One run on two or three threads: the truth of the next chunk is made on one thread while
//! another measures and tabulates the previous one, and (for a run that writes files) a third
//! writes the chunk before (a pipeline of stages).
//!
//! Each stage runs on one thread and keeps its order, so the numbers are those of a single
//! thread bit for bit: the truth is the same function of the sample times, the sensors draw
//! their noise in sample order from the same stream, and the files get the same rows in the same
//! order. What changes is the wall-clock time, when cores are free (see docs/design.md §1, and
//! benches/README.md for the figures).
//!
//! Memory stays flat: at most two finished chunks wait between two stages, and their buffers go
//! back to the producer to be refilled.
use crate::error::{Error, RequestOption, Result, invalid, refused};
use std::num::NonZeroUsize;
use std::sync::mpsc;

/// How many threads one streamed run uses ([`crate::Scenario::stream`] and the calls built on
/// it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RunThreads {
    /// Truth, sensors and outputs on the caller's thread.
    One,
    /// Two stages. A run that writes files ([`crate::Scenario::stream_to_files`]) makes its truth
    /// and readings on a second thread and writes them on the caller's (formatting CSV takes
    /// about as long as the rest); any other run makes its truth a chunk ahead on a second
    /// thread, its readings on the caller's.
    Two,
    /// Three stages: the truth a chunk ahead on one thread, the readings on a second and, for a
    /// run that writes files, the files on the caller's; [`RunThreads::Two`] for any other run.
    Three,
    /// As many stages as this process may use cores ([`std::thread::available_parallelism`]:
    /// affinity masks and cgroup quotas count), at most three, when the run has at least
    /// [`AUTO_MIN_CHUNKS`] chunks; else [`RunThreads::One`].
    #[default]
    Auto,
}

/// The fewest chunks for which [`RunThreads::Auto`] starts a second thread: a shorter run has
/// too little to overlap for the thread's start (0.15–0.25 ms here) to pay — a run of a few
/// samples took three times as long on two threads, and one of 1 000 samples (two chunks of
/// 512, [`crate::run::simulate::stream_chunk`]) 0.37 ms against 0.34 ms on one.
pub const AUTO_MIN_CHUNKS: usize = 4;

/// The cores this process may use ([`std::thread::available_parallelism`]: affinity masks and
/// cgroup quotas count), 1 when the system does not say.
#[must_use]
pub fn available_cores() -> usize {
    std::thread::available_parallelism().map_or(1, NonZeroUsize::get)
}

impl RunThreads {
    /// From the most threads a user lets one run use (as a command line or Python gives it),
    /// named `field` in the error: `None` is [`RunThreads::Auto`], 1 is [`RunThreads::One`], 2
    /// [`RunThreads::Two`], 3 or more [`RunThreads::Three`] (a run has at most three stages to
    /// share out).
    ///
    /// # Errors
    /// [`Error::Invalid`] on `field` for a count below 1.
    pub fn at_most(count: Option<i64>, field: &str) -> Result<Self> {
        match count {
            None => Ok(Self::Auto),
            Some(1) => Ok(Self::One),
            Some(2) => Ok(Self::Two),
            Some(n) if n >= 3 => Ok(Self::Three),
            Some(n) => Err(invalid(field, format!("must be ≥ 1 thread, got {n}"))),
        }
    }

    /// The threads (1 to 3) a run of `chunks` chunks is split over.
    #[must_use]
    pub fn stages(self, chunks: usize) -> usize {
        match self {
            Self::One => 1,
            Self::Two => 2,
            Self::Three => 3,
            Self::Auto if chunks < AUTO_MIN_CHUNKS => 1,
            Self::Auto => available_cores().min(3),
        }
    }

    /// Whether a run of `chunks` chunks is split over two threads or more.
    #[must_use]
    pub fn pipelined(self, chunks: usize) -> bool {
        self.stages(chunks) >= 2
    }
}

/// What a stage hands each chunk to.
pub(crate) type Stage<'a, T> = &'a mut dyn FnMut(&[T]) -> Result<()>;

/// The chunks `produce` hands its callback (about `chunks` of them), given to `consume` in the
/// same order: on the caller's thread when `threads` is one for that many, else `produce` on a
/// second thread (a copy of each
/// chunk crosses over). The first error in that order wins — the consumer's for the chunks it
/// was given, then the producer's — as when both run on one thread.
///
/// # Errors
/// Whatever `produce` or `consume` returns; [`Error::Invalid`] on `threads` when the system
/// refuses a second thread.
pub(crate) fn run_in_stages<T: Clone + Send>(
    threads: RunThreads,
    chunks: usize,
    produce: impl FnOnce(Stage<'_, T>) -> Result<()> + Send,
    consume: Stage<'_, T>,
) -> Result<()> {
    if !threads.pipelined(chunks) {
        return produce(consume);
    }
    std::thread::scope(|scope| {
        // Two finished chunks may wait; the consumer hands emptied buffers back.
        let (full_tx, full_rx) = mpsc::sync_channel::<Vec<T>>(2);
        let (empty_tx, empty_rx) = mpsc::channel::<Vec<T>>();
        let producer = std::thread::Builder::new()
            .name("imukit-truth".into())
            .spawn_scoped(scope, move || {
                produce(&mut |chunk: &[T]| {
                    let mut buffer = empty_rx.try_recv().unwrap_or_default();
                    buffer.clear();
                    buffer.extend_from_slice(chunk);
                    // Refused only once the consumer has stopped, with an error of its own
                    // that takes precedence over this one.
                    full_tx.send(buffer).map_err(|_| stopped())
                })
            })
            .map_err(|e| {
                refused(
                    RequestOption::Threads,
                    format!("could not start a second thread ({e}); one thread would do"),
                )
            })?;
        let mut consumed = Ok(());
        for buffer in &full_rx {
            if let Err(e) = consume(&buffer) {
                consumed = Err(e);
                break;
            }
            // The producer may have finished and gone: then nobody needs the buffer back.
            let _ = empty_tx.send(buffer);
        }
        // A producer waiting to send learns that nobody will receive, and stops.
        drop(full_rx);
        let produced = producer
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        consumed.and(produced)
    })
}

fn stopped() -> Error {
    invalid("run", "the consumer of the truth stopped")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn numbers(n: usize) -> impl FnOnce(Stage<'_, u64>) -> Result<()> {
        move |emit| {
            let all: Vec<u64> = (0..n as u64).collect();
            all.chunks(7).try_for_each(emit)
        }
    }

    #[test]
    fn both_ways_give_the_chunks_in_order() {
        for threads in [RunThreads::One, RunThreads::Two] {
            let mut seen = Vec::new();
            run_in_stages(threads, 15, numbers(100), &mut |c: &[u64]| {
                seen.push(c.to_vec());
                Ok(())
            })
            .expect("runs");
            assert_eq!(seen.len(), 15, "{threads:?}");
            assert_eq!(seen.concat(), (0..100).collect::<Vec<u64>>(), "{threads:?}");
        }
    }

    #[test]
    fn the_consumers_error_wins_and_stops_the_producer() {
        let mut calls = 0;
        let err = run_in_stages(
            RunThreads::Two,
            1429,
            numbers(10_000),
            &mut |_: &[u64]| {
                calls += 1;
                if calls == 3 {
                    Err(invalid("sink", "full"))
                } else {
                    Ok(())
                }
            },
        )
        .expect_err("the sink refuses");
        assert_eq!(err.to_string(), "sink: full");
        assert_eq!(calls, 3);
    }

    #[test]
    fn the_producers_error_comes_after_the_chunks_it_made() {
        let produce = |emit: Stage<'_, u64>| {
            emit(&[1, 2])?;
            emit(&[3])?;
            Err(invalid("trajectory", "breaks at t = 3 s"))
        };
        let mut seen = Vec::new();
        let err = run_in_stages(RunThreads::Two, 2, produce, &mut |c: &[u64]| {
            seen.extend_from_slice(c);
            Ok(())
        })
        .expect_err("the producer refuses");
        assert_eq!(err.to_string(), "trajectory: breaks at t = 3 s");
        assert_eq!(seen, [1, 2, 3]);
    }

    #[test]
    fn a_users_count_of_threads_caps_the_stages_and_less_than_one_is_refused_by_name() {
        let at_most = |n| RunThreads::at_most(n, "--threads").ok();
        assert_eq!(at_most(None), Some(RunThreads::Auto));
        assert_eq!(at_most(Some(1)), Some(RunThreads::One));
        assert_eq!(at_most(Some(2)), Some(RunThreads::Two));
        assert_eq!(at_most(Some(3)), Some(RunThreads::Three));
        assert_eq!(at_most(Some(64)), Some(RunThreads::Three));
        for n in [0, -3] {
            let err = RunThreads::at_most(Some(n), "--threads").expect_err("no thread");
            assert_eq!(
                err.to_string(),
                format!("--threads: must be ≥ 1 thread, got {n}")
            );
        }
        assert!(!RunThreads::One.pipelined(100) && RunThreads::Two.pipelined(1));
        assert!(!RunThreads::Auto.pipelined(AUTO_MIN_CHUNKS - 1));
        let auto = RunThreads::Auto.stages(AUTO_MIN_CHUNKS);
        assert_eq!(auto, available_cores().min(3));
    }
}
