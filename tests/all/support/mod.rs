//! Harnesses the end-to-end tests share: a headless browser session and the fuzzing helpers.

pub mod browser;
pub mod fuzz;
