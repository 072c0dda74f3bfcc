//! emray: a Whitted-style ray tracer for NFF scenes whose ray queries run on Intel
//! Embree (feature `embree`, default) or on a pure-Rust BVH.
//!
//! The phases are separate: [`load`] parses a file into a backend-free [`scene::Scene`],
//! [`accel`] builds an acceleration structure over it, [`render`] traces rays through
//! that structure and [`output`] writes the film.
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod accel;
pub mod batch;
pub mod bench;
pub mod geometry;
pub mod job;
pub mod load;
pub mod math;
pub mod output;
pub mod quality;
pub mod radiosity;
pub mod render;
pub mod scene;
pub mod spd;

pub use accel::{Accel, Backend, Hit};
pub use render::{Region, RenderSettings, RenderStats};
pub use scene::Scene;
