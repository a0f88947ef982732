//! `fill`, `diff` and `check`.

use super::args::{CheckArgs, DiffArgs, FillArgs};
use super::ExitStatus;

pub fn fill(_a: &FillArgs) -> ExitStatus {
    eprintln!("error: fill is not implemented yet");
    ExitStatus::Error
}

pub fn diff(_a: &DiffArgs) -> ExitStatus {
    eprintln!("error: diff is not implemented yet");
    ExitStatus::Error
}

pub fn check(_a: &CheckArgs) -> ExitStatus {
    eprintln!("error: check is not implemented yet");
    ExitStatus::Error
}
