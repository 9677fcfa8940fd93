//! The files a controller loads, written from plain values (what goes where is decided by the
//! `compensation` crate; nothing here computes kinematics).
//!
//! - [`isg`]: ISG-kernel's volumetric compensation file (`ISG_CSV`);
//! - [`linuxcnc`]: a HAL file of `setp` lines for a kinematics module's pins, and the joint
//!   compensation files `[JOINT_n] COMP_FILE` reads.
//! - [`siemens`]: SINUMERIK part programs and initialisation files: a swivel data record
//!   (`$TC_CARR`), the five-axis transformation's machine data, and the measuring-system and
//!   sag compensation tables (`$AA_ENC_COMP`, `$AN_CEC`).

pub mod isg;
pub mod linuxcnc;
pub mod siemens;
