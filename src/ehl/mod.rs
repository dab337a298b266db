//! The full-system EHL solver: unknown layout, preallocation, residual and exact Jacobian
//! of the coupled elasticity + Reynolds + load-balance system, and the Newton driver.
pub mod condensed;
pub mod driver;
pub mod layout;
pub mod post;
pub mod prealloc;
pub mod step;
pub mod system;
