//! Embree backend (being written).
#![allow(missing_docs)]
use crate::accel::{Accel, AccelStats, Hit};
use crate::math::Ray;
use crate::scene::Scene;

#[derive(Debug, thiserror::Error)]
#[error("embree: {0}")]
pub struct EmbreeError(pub String);

pub struct EmbreeAccel;
impl EmbreeAccel {
    pub fn build(_scene: &Scene) -> Result<Self, EmbreeError> {
        Err(EmbreeError("not built".into()))
    }
}
impl Accel for EmbreeAccel {
    fn intersect(&self, _ray: &Ray) -> Option<Hit> {
        None
    }
    fn occluded(&self, _ray: &Ray) -> bool {
        false
    }
    fn stats(&self) -> AccelStats {
        AccelStats::default()
    }
}
