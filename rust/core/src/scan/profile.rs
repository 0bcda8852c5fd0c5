//! Where a scan's threads wait: per stage of a block, the wall time, the busy time of
//! every pool thread (the summed durations of the stage's tasks that ran on it) and the
//! least wall time the stage's task sizes allow on the pool's thread count. A
//! benchmark's measure of the scan's own parallel efficiency, apart from the machine's
//! (a task's duration counts as busy even while the machine lets its thread wait), so
//! that the speed-up the scan allows can be told from what the hardware gives.
//!
//! A stage is run as *steps* separated by barriers (the perfect-balance checks: one
//! step; the continuation: one step per wave). A step whose tasks take `busy` in all,
//! the longest `longest`, cannot end sooner than `max(busy / 2, longest)` after it began
//! on two threads; serial work (a step of one task) takes its own time on any thread
//! count. Summed over steps this is the stage's *two-thread bound*: from a one-thread
//! run (task durations undisturbed by a second thread), `wall / bound` is the
//! two-thread speed-up the scan's structure allows.

use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::time::{Duration, Instant};

/// The stages, in [`profile`]'s order.
pub const STAGES: [&str; 5] = ["balance", "seeds", "waves", "glue", "rows"];
pub(crate) const BALANCE: usize = 0;
/// Seed simulations with their solves, then the Floquet analyses of the orbits kept.
pub(crate) const SEEDS: usize = 1;
/// The continuation waves' parallel part (the target points' corrections and Floquet).
pub(crate) const WAVES: usize = 2;
/// Serial work between the parallel steps: the block's models, each wave's targets and
/// the merge of its results.
pub(crate) const GLUE: usize = 3;
pub(crate) const ROWS: usize = 4;

/// Pool threads told apart (busy time of higher thread indices is added to the last).
pub const THREADS: usize = 16;

struct Stage {
    wall: AtomicU64,
    bound: AtomicU64,
    longest: AtomicU64,
    steps: AtomicU64,
    tasks: AtomicU64,
    busy: [AtomicU64; THREADS],
}

static PROFILE: [Stage; 5] = [const {
    Stage {
        wall: AtomicU64::new(0),
        bound: AtomicU64::new(0),
        longest: AtomicU64::new(0),
        steps: AtomicU64::new(0),
        tasks: AtomicU64::new(0),
        busy: [const { AtomicU64::new(0) }; THREADS],
    }
}; 5];

/// Per stage (see [`STAGES`]), summed over the blocks of the scans this process ran:
/// `[wall, bound, span, steps, tasks, busy of pool thread 0, 1, ..., THREADS - 1]`,
/// times in seconds. `bound`: the two-thread bound; `span`: the summed longest task of
/// every step (the least wall time on any number of threads). Blocks that run at once
/// (several per grid) each count their own wall time.
pub fn profile() -> Vec<Vec<f64>> {
    let s = |a: &AtomicU64| a.load(Relaxed) as f64 * 1e-9;
    PROFILE
        .iter()
        .map(|st| {
            let mut v = vec![
                s(&st.wall),
                s(&st.bound),
                s(&st.longest),
                st.steps.load(Relaxed) as f64,
                st.tasks.load(Relaxed) as f64,
            ];
            v.extend(st.busy.iter().map(s));
            v
        })
        .collect()
}

/// A task's duration and the pool thread it ran on.
pub type Task = (Option<usize>, Duration);

/// Runs `f` as a task of a step, returning its result and its [`Task`] record.
pub(crate) fn timed<R>(f: impl FnOnce() -> R) -> (R, Task) {
    let t = Instant::now();
    let r = f();
    (r, (rayon::current_thread_index(), t.elapsed()))
}

/// Records a step of `stage` that took `wall` and ran `tasks`.
pub(crate) fn step(stage: usize, wall: Duration, tasks: &[Task]) {
    let st = &PROFILE[stage];
    let busy: Duration = tasks.iter().map(|t| t.1).sum();
    let longest = tasks.iter().map(|t| t.1).max().unwrap_or(wall);
    let bound = if tasks.is_empty() {
        wall
    } else {
        (busy / 2).max(longest)
    };
    for &(i, d) in tasks {
        let i = i.unwrap_or(0).min(THREADS - 1);
        st.busy[i].fetch_add(d.as_nanos() as u64, Relaxed);
    }
    st.wall.fetch_add(wall.as_nanos() as u64, Relaxed);
    st.bound.fetch_add(bound.as_nanos() as u64, Relaxed);
    st.longest.fetch_add(longest.as_nanos() as u64, Relaxed);
    st.steps.fetch_add(1, Relaxed);
    st.tasks.fetch_add(tasks.len() as u64, Relaxed);
}

/// Records serial work of `stage` that took `wall`, on the current thread.
pub(crate) fn serial(stage: usize, wall: Duration) {
    step(stage, wall, &[(rayon::current_thread_index(), wall)]);
}
