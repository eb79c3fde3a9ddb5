//! How a command ends: the exit codes, one scheme for every command, and the failure that carries its
//! code and the sentence that explains it.

/// The exit codes, one scheme for every command (listed in `--help`, docs/cli.md and the README, "Exit
/// codes").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exit {
    /// Success.
    Ok = 0,
    /// A check failed (crosscheck found lines that differ), or the machinery failed (a tracer error).
    Failed = 1,
    /// Bad input or usage: a scene that cannot be read, a nonsense option.
    BadInput = 2,
    /// A file could not be written, or a run state could not be read (the system refused) or is held
    /// by a live run.
    Io = 3,
    /// Interrupted (Ctrl-C): the report printed covers the lines gathered so far.
    Interrupted = 130,
}

/// A failure with its exit code and the sentence that explains it.
#[derive(Debug)]
pub struct Failure {
    /// The exit code.
    pub code: Exit,
    /// The sentence for standard error.
    pub message: String,
}

/// A library error that tells whether the user's input is at fault.
pub trait InputError: std::fmt::Display {
    /// Whether the input (a scene, materials, settings) is at fault, not the machinery.
    fn is_bad_input(&self) -> bool;
}

macro_rules! input_errors {
    ($($t:ty),*) => {$(
        impl InputError for $t {
            fn is_bad_input(&self) -> bool {
                <$t>::is_bad_input(self)
            }
        }
    )*};
}

input_errors!(
    scene_complexity::AnalysisError,
    scene_complexity::refine::RefineError,
    scene_complexity::reproduce::ReproduceError,
    scene_complexity::calibrate::CalibrationError
);

impl Failure {
    /// A library error: bad input (2) when the input is at fault, else a failure (1).
    pub fn of(e: impl InputError) -> Self {
        Failure {
            code: if e.is_bad_input() {
                Exit::BadInput
            } else {
                Exit::Failed
            },
            message: e.to_string(),
        }
    }

    /// Bad input (exit code 2).
    pub fn bad_input(message: impl ToString) -> Self {
        Failure {
            code: Exit::BadInput,
            message: message.to_string(),
        }
    }
}
