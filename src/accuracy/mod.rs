//! The accuracy tools: how far an image is from a reference ([`metrics`], used by
//! `emray compare`), how the renderer holds up numerically ([`stress`], used by
//! `emray stress` and `tests/stability.rs`), and what each speed/accuracy knob costs
//! in error against time ([`study`], used by `emray study`); [`moved`] moves and scales
//! NFF scenes for the invariance checks; [`hard_triangles`] casts rays at huge, sliver
//! and grazing triangles on both backends against the f64 reference.
//!
//! [`metrics`] (FLIP through `nv-flip`, whose build compiles C++) and [`study`] (its
//! plots through `plotters`) exist only with the `quality` cargo feature (on by
//! default); [`stress`] needs neither and is always built.

pub mod hard_triangles;
#[cfg(feature = "quality")]
pub mod metrics;
pub mod moved;
pub mod stress;
#[cfg(feature = "quality")]
pub mod study;
