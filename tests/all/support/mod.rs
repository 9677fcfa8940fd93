//! Harnesses the end-to-end tests share: a headless browser session, the fuzzing helpers and the real LinuxCNC.

pub mod browser;
pub mod fuzz;
pub mod linuxcnc;
