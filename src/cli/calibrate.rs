//! `conduit calibrate`: tool-centre-point (pivot) calibration and frame registration.

use super::Failure;

/// Arguments of `conduit calibrate`.
#[derive(Debug, clap::Args)]
pub struct CalibrateArgs {}

pub(crate) fn run(_args: CalibrateArgs) -> Result<(), Failure> {
    Err(Failure::Usage(
        "conduit calibrate: not available".to_owned(),
    ))
}
