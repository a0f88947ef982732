//! urdf-inertia: correct `<inertial>` elements for URDF robot descriptions, computed from the collision
//! geometry with Mirtich's polyhedral mass properties (1996).
//!
//! Data flows one way, each stage a module:
//! URDF scan ([`urdf`]) → resolve and load geometry ([`mesh`]) → mass core ([`mass`]) →
//! per-link composition ([`fill`]) → splice `<inertial>` into the original bytes ([`urdf::write`]).
//! xacro sources are expanded first ([`xacro`]), with a map back to their files and lines.
#![forbid(unsafe_code)]

pub mod compare;
pub mod density;
pub mod diagnostic;
pub mod fill;
mod geometry;
pub mod input;
pub mod mass;
pub mod mesh;
pub mod overlap;
pub mod problem;
pub mod text;
pub mod threads;
pub mod urdf;
pub mod xacro;

/// A small deterministic generator for the unit tests (xorshift64; the same sequence on every run).
#[cfg(test)]
pub(crate) fn xorshift(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}

/// A uniform f64 in [0, 1) for the unit tests, from a 64-bit LCG (Knuth's MMIX constants).
#[cfg(test)]
pub(crate) fn lcg_unit(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}
