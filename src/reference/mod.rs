//! Exact answers the renders are judged against.
//!
//! [`visibility::visible_fraction`] integrates the unoccluded part of a disk light seen from a
//! receiver point to ~1e-10; [`on_axis`] gives the closed-form umbra and penumbra radii of a
//! sphere above a plane under a coaxial disk light (FACTS.md).

pub mod ambient;
pub mod on_axis;
pub mod quadrature;
pub mod visibility;

pub use on_axis::OnAxis;
pub use quadrature::Integral;
pub use visibility::{irradiance_fraction_estimate, occluders, visible_fraction, visible_fraction_estimate};
