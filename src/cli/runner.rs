//! A scene ready to run: its tracer, a thread pool, and the Ctrl-C handler that stops a run cleanly.

use std::sync::Arc;

use scene_complexity::{analyze, Analysis};
use scene_complexity::{make_tracer, Tracer};
use scene_complexity::{LineBound, LinesThrough, RunControl, RunSpec, Tracing};
use scene_complexity::{ReadPolicy, Scene, SceneOptions};

use super::args::RunOptions;
use super::exit::{Exit, Failure};
use super::input::load_scene;
use super::{progress, report};

/// A scene with its tracer and thread pool, ready to run analyses.
pub struct Runner {
    pub scene: Scene,
    /// `None` once released ([`Runner::release_tracer`]).
    tracer: Option<Box<dyn Tracer>>,
    pub pool: rayon::ThreadPool,
    pub threads: usize,
    /// The backend and query the tracer was built with.
    pub tracing: Tracing,
    /// How long building the tracer's acceleration structure took, in seconds.
    pub build_seconds: f64,
    pub control: Arc<RunControl>,
}

/// What a progress bar adds to its label for a run drawn as `bound` says: it counts the lines drawn,
/// through a container fewer than --lines asked, and says so.
pub fn drawn_label(bound: LineBound) -> &'static str {
    match bound {
        LineBound::Sphere => "",
        LineBound::Box => "drawn through the box",
        LineBound::Polytope => "drawn through the polytope",
    }
}

impl Runner {
    /// Loads the scene and builds its tracer and thread pool.
    pub fn new(name: &str, opts: &RunOptions) -> Result<Runner, Failure> {
        Runner::with(
            name,
            (&opts.input.options(), &opts.input.policy()),
            opts.tracing(),
            opts.threads.value,
        )
    }

    /// Loads the scene `name` read as `reading` asks (its options, and what the reading may touch), and
    /// builds the tracer `tracing` asks for and a pool of `threads` threads.
    pub fn with(
        name: &str,
        (options, policy): (&SceneOptions, &ReadPolicy),
        tracing: Tracing,
        threads: Option<usize>,
    ) -> Result<Runner, Failure> {
        let scene = load_scene(name, options, policy)?;
        let building = std::time::Instant::now();
        let tracer =
            make_tracer(tracing.backend, &scene, tracing.query).map_err(Failure::bad_input)?;
        let build_seconds = building.elapsed().as_secs_f64();
        let (threads, pool) = thread_pool(threads)?;
        let control = Arc::new(RunControl::default());
        watch_ctrl_c(&control);
        Ok(Runner {
            scene,
            tracer: Some(tracer),
            pool,
            threads,
            tracing,
            build_seconds,
            control,
        })
    }

    /// Runs `work` in the runner's thread pool while a progress bar shows (of `total` lines when known).
    pub fn in_pool<T: Send>(
        &self,
        total: Option<u64>,
        label: &str,
        work: impl FnOnce() -> T + Send,
    ) -> T {
        progress::while_running(&self.control, total, label, || self.pool.install(work))
    }

    /// Runs one analysis of `cfg` with a progress bar (`label` says which run). Its `lines` are counted
    /// through the bounding sphere, and its bound is the one `--lines-through auto` chooses for the scene
    /// ([`RunSpec::through`]), as `scx analyze` settles it: the same arguments draw the same lines in
    /// every command.
    pub fn analyze(&self, cfg: RunSpec, label: &str) -> Result<Analysis, Failure> {
        let cfg = cfg.through(&self.scene, LinesThrough::Auto);
        let label = match (label, drawn_label(cfg.bound)) {
            (label, "") => label.to_string(),
            ("", drawn) => drawn.to_string(),
            (label, drawn) => format!("{label}, {drawn}"),
        };
        progress::while_running(&self.control, Some(cfg.lines), &label, || {
            self.pool
                .install(|| analyze(&self.scene, self.tracer(), &cfg, &self.control))
        })
        .map_err(Failure::of)
    }

    /// The scene's tracer.
    ///
    /// # Panics
    /// When it was released ([`Runner::release_tracer`]).
    pub fn tracer(&self) -> &dyn Tracer {
        self.tracer
            .as_deref()
            .expect("the tracer is used only before it is released")
    }

    /// Frees the tracer once no more lines will be cast: on a large scene its acceleration structure
    /// is a good part of the memory, which the measures then need.
    pub fn release_tracer(&mut self) {
        self.tracer = None;
    }

    /// Facts about the run for the reports.
    pub fn info(&self) -> report::RunInfo<'_> {
        report::RunInfo {
            scene: &self.scene,
            tracing: self.tracing,
            threads: self.threads,
            build_seconds: self.build_seconds,
            shard: None,
        }
    }
}

/// The worker threads (absent or 0: all cores) and a rayon pool of that size.
pub fn thread_pool(threads: Option<usize>) -> Result<(usize, rayon::ThreadPool), Failure> {
    let threads = threads.filter(|&t| t > 0).unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Failure {
            code: Exit::Failed,
            message: format!("cannot start {threads} threads: {e}"),
        })?;
    Ok((threads, pool))
}

/// The first Ctrl-C asks the run to stop and report what it gathered; a second one ends the program.
pub fn watch_ctrl_c(control: &Arc<RunControl>) {
    let control = Arc::clone(control);
    let presses = std::sync::atomic::AtomicU32::new(0);
    // Failing to install the handler only loses the clean stop: Ctrl-C then ends the program as usual.
    let _ = ctrlc::set_handler(move || {
        if presses.fetch_add(1, std::sync::atomic::Ordering::SeqCst) > 0 {
            std::process::exit(Exit::Interrupted as i32);
        }
        eprintln!("\nscx: stopping after the batches under way (Ctrl-C again to quit now)");
        control.request_stop();
    });
}
