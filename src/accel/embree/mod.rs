//! The Intel Embree backend (feature `embree`): the only `unsafe` code in the crate.
//!
//! - `sys`: bindgen's bindings of the installed Embree header (3 or 4, see `build.rs`);
//! - `device`: the device, its error callback and [`EmbreeError`];
//! - `scene`: the build (triangles natively, one user geometry per analytic kind) and
//!   the committed scene the queries run on;
//! - `user`: the user-geometry callbacks, which call the shared `geometry::`
//!   intersectors and keep their panics from unwinding into Embree;
//! - `group`: the order that puts neighbouring primitives together when one Embree
//!   primitive stands for several (large scenes).
//!
//! Geometry ids are the [`Kind`](crate::geometry::Kind) discriminants and primitive ids
//! the index within the kind, exactly as the BVH reports them. Embree 3 and 4 differ in
//! the query functions and the callback argument structs; `#[cfg(embree3)]` and
//! `#[cfg(embree4)]` (set by `build.rs` from the header it found) bridge that here and
//! nowhere else.
#![allow(unsafe_code)]
#![warn(unsafe_op_in_unsafe_fn, clippy::undocumented_unsafe_blocks)]

mod device;
mod error;
mod group;
mod scene;
mod sys;
mod user;

#[cfg(test)]
mod tests;

pub use error::EmbreeError;

use crate::accel::{
    Accel, AccelStats, Backend, BackendOptions, Hit, embree_compact_for, embree_group_for,
    shadow_packet_width_for,
};
use crate::math::Ray;
use crate::scene::Scene;
use device::Device;
use scene::CommittedScene;
use std::sync::{Arc, Mutex};

/// A committed Embree scene over a [`Scene`]'s primitives, which it borrows: its
/// user-geometry callbacks read the scene's analytic primitives where they are.
///
/// Immutable once built, and `Send + Sync`: queries run from any number of threads.
/// Dropping it releases the scene (then frees the user data its callbacks read), then
/// its hold on the device, which the process shares (`shared_device`).
#[derive(Debug)]
pub struct EmbreeAccel<'s> {
    // Fields drop in declaration order: the scene before the device.
    scene: CommittedScene<'s>,
    device: Arc<Device>,
    prims: usize,
    bytes: usize,
    detail: String,
    /// Rays per packet for [`Accel::intersect_coherent`] (0: one by one).
    packet_width: u32,
    /// Rays per packet for [`Accel::occluded_batch`] (0: one by one).
    shadow_packet_width: u32,
}

/// The process's Embree device for `threads` build threads, created at the first
/// build that asks for it with the configuration `threads=N` (as `rtcNewDevice`
/// documents it) and kept for the process's life: one device per process, or one per
/// thread count for a process whose builds run on pools of different sizes.
fn shared_device(threads: usize) -> Result<Arc<Device>, EmbreeError> {
    static DEVICES: Mutex<Vec<(usize, Arc<Device>)>> = Mutex::new(Vec::new());
    let mut devices = DEVICES.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, d)) = devices.iter().find(|(t, _)| *t == threads) {
        return Ok(Arc::clone(d));
    }
    let device = Arc::new(Device::new(&format!("threads={threads}"))?);
    devices.push((threads, Arc::clone(&device)));
    Ok(device)
}

impl<'s> EmbreeAccel<'s> {
    /// Build with emray's defaults: medium build quality, robust traversal.
    pub fn build(scene: &'s Scene) -> Result<EmbreeAccel<'s>, EmbreeError> {
        EmbreeAccel::build_with(scene, &BackendOptions::new(Backend::Embree))
    }

    /// Build with `options` (build quality, robust traversal, packet width), on the
    /// process's device for the current rayon pool's thread count. Robust traversal
    /// (`RTC_SCENE_FLAG_ROBUST` on every scene: the top level and each instanced
    /// object's) avoids the arithmetic shortcuts that can let a ray slip between two
    /// triangles sharing an edge, at some cost in speed.
    pub fn build_with(
        scene: &'s Scene,
        options: &BackendOptions,
    ) -> Result<EmbreeAccel<'s>, EmbreeError> {
        let device = shared_device(rayon::current_num_threads())?;
        let (quality, robust) = (options.embree_quality, options.embree_robust);
        let prims = scene.prim_count_with_instances();
        let compact = options
            .embree_compact
            .unwrap_or_else(|| embree_compact_for(prims));
        let group = options
            .embree_group
            .unwrap_or_else(|| embree_group_for(prims, options.camera_rays))
            .max(1);
        let before = device.allocated_bytes();
        let committed =
            CommittedScene::build(&device, scene, quality, robust, compact, group as usize)?;
        let shadow_packet_width = options
            .shadow_packet_width
            .unwrap_or_else(|| shadow_packet_width_for(&committed.kinds));
        let api = if cfg!(embree4) { "embree4" } else { "embree3" };
        let detail = format!(
            "{}, {api} API (headers {}), {} traversal, {} build quality{}{}, shadow rays {}",
            device.describe(),
            env!("EMRAY_EMBREE_HEADER_VERSION"),
            if robust { "robust" } else { "fast" },
            quality.name(),
            if compact { ", compact" } else { "" },
            if group > 1 {
                format!(", analytic primitives in groups of at most {group}")
            } else {
                String::new()
            },
            match shadow_packet_width {
                4 | 8 | 16 => format!("in packets of {shadow_packet_width}"),
                _ => "one by one".to_string(),
            },
        );
        Ok(EmbreeAccel {
            // Embree's own allocations for this scene (hierarchy, triangle buffers), read
            // after the commit has freed the build's temporaries (on a device building
            // one scene at a time), and what emray keeps for the callbacks besides the
            // scene's primitives, which they read where they are.
            bytes: device.allocated_bytes().saturating_sub(before) + committed.rust_bytes(),
            scene: committed,
            device,
            prims,
            detail,
            packet_width: options.packet_width,
            shadow_packet_width,
        })
    }

    /// Cast coherent rays ([`Accel::intersect_coherent`]) in packets of `width` (4, 8
    /// or 16; anything else casts them one by one).
    pub fn with_packet_width(mut self, width: u32) -> Self {
        self.packet_width = width;
        self
    }

    /// Cast shadow-ray batches ([`Accel::occluded_batch`]) in packets of `width` (4, 8
    /// or 16; anything else casts them one by one).
    pub fn with_shadow_packet_width(mut self, width: u32) -> Self {
        self.shadow_packet_width = width;
        self
    }

    /// The Embree library version as `major * 10000 + minor * 100 + patch`
    /// (`RTC_DEVICE_PROPERTY_VERSION`).
    pub fn version(&self) -> u32 {
        let v = self
            .device
            .property(sys::RTCDeviceProperty::RTC_DEVICE_PROPERTY_VERSION);
        u32::try_from(v).unwrap_or(0)
    }
}

/// Hits are reported in `(max(tmin, 0), tmax)`: Embree requires rays to start at or
/// after their origin.
impl Accel for EmbreeAccel<'_> {
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.scene.intersect(ray)
    }

    #[inline(always)]
    fn occluded(&self, ray: &Ray) -> bool {
        self.scene.occluded(ray)
    }

    fn intersect_coherent(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        self.scene
            .intersect_packets(rays, hits, self.packet_width as usize);
    }

    fn occluded_batch(&self, rays: &[Ray], occluded: &mut [bool]) {
        self.scene
            .occluded_packets(rays, occluded, self.shadow_packet_width as usize);
    }

    fn stats(&self) -> AccelStats {
        AccelStats {
            backend: "embree",
            prims: self.prims,
            nodes: 0,
            bytes: self.bytes,
            detail: self.detail.clone(),
            kinds: self.scene.kinds.clone(),
        }
    }
}
