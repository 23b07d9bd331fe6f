//! Robot set-up and the robot calibration loop: what a robot arm needs beside the conformal
//! path itself.
//!
//! Place in the pipeline: around the robot branch of `conform`. Before a program runs, the tool
//! centre point is calibrated ([`tcp`], from flange poses or joint angles through [`kinematics`])
//! and the part's frame registered to the robot's ([`frames`]); after a print, a calibration
//! [`pattern`] is measured and the path moved by the measured gaps ([`compensate`]), pass after
//! pass. The tool orientation along a conformal path is part of the conform plan
//! (`conform::orient`), and the robot programs are written by `emit::robot`.

pub mod compensate;
pub mod frames;
pub mod kinematics;
pub mod pattern;
pub mod tcp;
