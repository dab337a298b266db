//! The equivalent elastic solid (docs/model.md section 6): DOF numbering, assembly of the
//! P2 elasticity system and of contact-face pressure loads, and the subsurface stresses.
pub mod assembly;
pub mod condense;
pub mod dofmap;
pub mod hertz_load;
pub mod hertz_stress;
pub mod stress;
