//! Writers of machine programs and reports: everything downstream of the [`Program`].
//!
//! Place in the pipeline: Program → **emit** → files. Writers consume a
//! [`Program`](crate::program::Program) and the [`Config`](crate::config::Config); they never
//! re-slice or look further upstream.
//!
//! - [`gcode`]: G-code for Marlin, RepRapFirmware and Klipper, filament and paste tools.
//!
//! [`Program`]: crate::program::Program

pub mod gcode;
pub mod preview;
pub mod robot;
pub mod route_svg;
