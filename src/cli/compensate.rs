//! `conduit compensate`: gap compensation of a robot path from measured gaps.

use super::Failure;

/// Arguments of `conduit compensate`.
#[derive(Debug, clap::Args)]
pub struct CompensateArgs {}

pub(crate) fn run(_args: CompensateArgs) -> Result<(), Failure> {
    Err(Failure::Usage(
        "conduit compensate: not available".to_owned(),
    ))
}
