//! The files a controller loads, written from plain values (what goes where is decided by the
//! `compensation` crate; nothing here computes kinematics).
//!
//! - [`linuxcnc`]: a HAL file of `setp` lines for a kinematics module's pins, and the joint
//!   compensation files `[JOINT_n] COMP_FILE` reads.

pub mod linuxcnc;
