//! Progress reporting and cancellation, shared by every stage.
//!
//! A stage receives a [`Progress`] and calls [`Progress::report`] in its
//! loops. The sink behind it (the CLI's logger, the web worker's message
//! poster, a test's recorder) answers whether to go on; a `false` answer
//! turns into [`Cancelled`], which the stage returns at once. One mechanism
//! for both: the web worker cannot receive a "cancel" message while wasm
//! runs, so its sink reads a flag the page can set (see `web/`).

/// The run was cancelled by the user.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("cancelled")]
pub struct Cancelled;

/// A stage's handle on the progress sink: a function receiving `(stage,
/// fraction of the stage done in [0, 1], message)` that returns `false` to
/// cancel.
pub struct Progress<'a> {
    sink: &'a mut dyn FnMut(&str, f32, &str) -> bool,
    stage: &'static str,
}

impl<'a> Progress<'a> {
    pub fn new(
        sink: &'a mut dyn FnMut(&str, f32, &str) -> bool,
        stage: &'static str,
    ) -> Progress<'a> {
        Progress { sink, stage }
    }

    /// Reports `fraction` of the current stage; `Err(Cancelled)` if the sink
    /// asked to stop.
    pub fn report(&mut self, fraction: f32, message: &str) -> Result<(), Cancelled> {
        if (self.sink)(self.stage, fraction.clamp(0.0, 1.0), message) {
            Ok(())
        } else {
            Err(Cancelled)
        }
    }

    /// The same sink, reporting under another stage name.
    pub fn set_stage(&mut self, stage: &'static str) {
        self.stage = stage;
    }

    pub fn stage(&self) -> &'static str {
        self.stage
    }
}

/// Runs `f` with a sink that never cancels and ignores every report.
pub fn silently<T>(stage: &'static str, f: impl FnOnce(&mut Progress<'_>) -> T) -> T {
    let mut ignore = |_: &str, _: f32, _: &str| true;
    let mut progress = Progress::new(&mut ignore, stage);
    f(&mut progress)
}
