//! What a controller's own data can hold of a machine description: the parameters of its
//! kinematics and the axes it drives, computed from the (corrected) description. The files are
//! written by `formats::controllers`.
//!
//! - [`linuxcnc`]: LinuxCNC's table-table kinematics modules `xyzac-trt-kins` and
//!   `xyzbc-trt-kins` (their HAL pins and joint map).

pub mod linuxcnc;
