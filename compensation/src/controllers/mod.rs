//! What a controller's own data can hold of a machine description: the parameters of its
//! kinematics and the axes it drives, computed from the (corrected) description. The files are
//! written by `formats::controllers`.
//!
//! - [`isg`]: ISG-kernel's volumetric compensation (Beckhoff TwinCAT CNC): the errors under
//!   its ISO 230 names, in its units;
//! - [`linuxcnc`]: LinuxCNC's table-table kinematics modules `xyzac-trt-kins` and
//!   `xyzbc-trt-kins` (their HAL pins and joint map).
//! - [`siemens`]: SINUMERIK's swivel data records (`$TC_CARR`) and its interpolatory
//!   compensation tables (`$AA_ENC_COMP`, `$AN_CEC`).

pub mod isg;
pub mod linuxcnc;
pub mod siemens;
