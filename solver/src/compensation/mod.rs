//! What was identified, put back onto the machine: the errors at any pose, the corrected kinematic description, and axis compensation tables.

pub mod kinematics;
pub mod tables;
pub mod values;
