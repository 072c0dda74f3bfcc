//! User geometry: one Embree geometry per analytic shape kind, holding all primitives of
//! that kind. Its callbacks call the same `geometry::` intersectors as the pure-Rust BVH,
//! so both backends give the same hits for every analytic kind, bit for bit.
//!
//! The callbacks are panic-free by construction (a panic across `extern "C"` aborts):
//! no indexing that can fail (`get`), no allocation, no locks, only float arithmetic in
//! the intersectors. They keep no shared counters (a shared atomic costs ~30% at two
//! threads).
//!
//! Embree 3 and 4 differ here in two ways, bridged below:
//! - the `context` member of the argument structs is an `RTCIntersectContext` (3) or an
//!   `RTCRayQueryContext` (4); both have the `instID` stack we copy into the hit;
//! - Embree 4's single-ray traversal takes the `valid` mask back as the result
//!   (`return mask != 0`): a callback must set `valid[i] = 0` for a ray that misses,
//!   or the miss counts as a hit (and an occlusion ray would always be occluded).
//!   Embree 3 ignores writes to `valid`; we leave it alone there.
//!
//! We register no intersection filters, so the callbacks do not invoke them
//! (`rtcFilterIntersection` in 3, `rtcInvokeIntersectFilterFromGeometry` in 4).

use std::ffi::c_void;

use super::sys;
use crate::geometry::Intersect;
use crate::math::{Aabb, Ray, Vec3};

/// An analytic shape the user-geometry callbacks can intersect: any
/// [`Intersect`] implementor that can be shared across threads.
pub(super) trait UserShape: Intersect + Clone + Send + Sync + 'static {}

impl<T: Intersect + Clone + Send + Sync + 'static> UserShape for T {}

/// The user data of one user geometry: its primitives, indexed by Embree's `primID`.
/// Lives in a `Box` owned by the `EmbreeAccel`, so the pointer Embree holds stays valid
/// until the scene has been released.
#[derive(Debug)]
pub(super) struct UserPrims<T> {
    pub(super) items: Box<[T]>,
    /// The primitive id reported for each item (its index in the scene's list).
    pub(super) ids: Box<[u32]>,
}

impl<T> UserPrims<T> {
    /// The pointer registered with `rtcSetGeometryUserData`.
    pub(super) fn as_user_ptr(&self) -> *mut c_void {
        std::ptr::from_ref(self).cast_mut().cast()
    }
}

/// The ray-query context type the callbacks receive.
#[cfg(embree3)]
type Context = sys::RTCIntersectContext;
/// The ray-query context type the callbacks receive.
#[cfg(embree4)]
type Context = sys::RTCRayQueryContext;

/// Word offsets of the members of `RTCRayN` in Embree's SoA layout: member `k` of ray
/// `i` in a packet of `N` is 32-bit word `k·N + i` (the header's `RTCRayN_*` accessors,
/// which are C++-only). The hit (`RTCHitN`) starts at word `12·N` of an `RTCRayHitN`.
mod soa {
    pub const ORG_X: usize = 0;
    pub const ORG_Y: usize = 1;
    pub const ORG_Z: usize = 2;
    pub const TNEAR: usize = 3;
    pub const DIR_X: usize = 4;
    pub const DIR_Y: usize = 5;
    pub const DIR_Z: usize = 6;
    pub const TFAR: usize = 8;
    pub const RAY_WORDS: usize = 12;
    pub const NG_X: usize = 0;
    pub const NG_Y: usize = 1;
    pub const NG_Z: usize = 2;
    pub const U: usize = 3;
    pub const V: usize = 4;
    pub const PRIM_ID: usize = 5;
    pub const GEOM_ID: usize = 6;
    pub const INST_ID: usize = 7;
}

/// A packet of `n` rays (or hits) in SoA layout starting at `base`.
#[derive(Clone, Copy)]
struct Packet {
    base: *mut u32,
    n: usize,
}

impl Packet {
    /// Pointer to member `field` of element `i`.
    ///
    /// # Safety
    /// `base` must point to a live packet of `n` elements with at least `field + 1`
    /// 32-bit members, and `i < n`.
    #[inline(always)]
    unsafe fn word(self, field: usize, i: usize) -> *mut u32 {
        // SAFETY: by the caller's contract the offset stays inside the packet.
        unsafe { self.base.add(field * self.n + i) }
    }

    /// # Safety
    /// As [`Packet::word`].
    #[inline(always)]
    unsafe fn get_f32(self, field: usize, i: usize) -> f32 {
        // SAFETY: as `word`; the words are plain 4-byte-aligned floats.
        f32::from_bits(unsafe { self.word(field, i).read() })
    }

    /// # Safety
    /// As [`Packet::word`], and Embree must allow writing the member.
    #[inline(always)]
    unsafe fn set_f32(self, field: usize, i: usize, value: f32) {
        // SAFETY: as `word`.
        unsafe { self.word(field, i).write(value.to_bits()) }
    }

    /// # Safety
    /// As [`Packet::set_f32`].
    #[inline(always)]
    unsafe fn set_u32(self, field: usize, i: usize, value: u32) {
        // SAFETY: as `word`.
        unsafe { self.word(field, i).write(value) }
    }

    /// Ray `i` in our terms (`tnear` → `tmin`, `tfar`, the closest hit so far, → `tmax`).
    ///
    /// # Safety
    /// `self` is a live `RTCRayN` (or `RTCRayHitN`) packet and `i < n`.
    #[inline(always)]
    unsafe fn ray(self, i: usize) -> Ray {
        // SAFETY: the ray members 0..12 exist for every ray of the packet.
        unsafe {
            Ray {
                org: Vec3::new(
                    self.get_f32(soa::ORG_X, i),
                    self.get_f32(soa::ORG_Y, i),
                    self.get_f32(soa::ORG_Z, i),
                ),
                dir: Vec3::new(
                    self.get_f32(soa::DIR_X, i),
                    self.get_f32(soa::DIR_Y, i),
                    self.get_f32(soa::DIR_Z, i),
                ),
                tmin: self.get_f32(soa::TNEAR, i),
                tmax: self.get_f32(soa::TFAR, i),
            }
        }
    }

    /// The hit part of an `RTCRayHitN` packet.
    ///
    /// # Safety
    /// `self` is a live `RTCRayHitN` packet.
    #[inline(always)]
    unsafe fn hits(self) -> Packet {
        Packet {
            // SAFETY: the hit members follow the 12 ray members of all `n` rays.
            base: unsafe { self.base.add(soa::RAY_WORDS * self.n) },
            n: self.n,
        }
    }
}

/// The instance-ID stack of the query context (`RTC_INVALID_GEOMETRY_ID` everywhere for
/// our single-level scenes), to be deep-copied into each hit as Embree requires.
///
/// # Safety
/// `context` is null or points to the live context of the current query.
#[inline(always)]
unsafe fn instance_ids(context: *const Context) -> [u32; sys::MAX_INSTANCE_LEVELS] {
    // SAFETY: by the caller's contract.
    match unsafe { context.as_ref() } {
        Some(c) => c.instID,
        None => [sys::INVALID_GEOMETRY_ID; sys::MAX_INSTANCE_LEVELS],
    }
}

/// The `instPrimID` stack (Embree 4.3+ with instance arrays).
///
/// # Safety
/// As [`instance_ids`].
#[cfg(embree_instance_array)]
#[inline(always)]
unsafe fn instance_prim_ids(context: *const Context) -> [u32; sys::MAX_INSTANCE_LEVELS] {
    // SAFETY: by the caller's contract.
    match unsafe { context.as_ref() } {
        Some(c) => c.instPrimID,
        None => [sys::INVALID_GEOMETRY_ID; sys::MAX_INSTANCE_LEVELS],
    }
}

/// Mark ray `i` as not hit by this primitive (Embree 4 reads `valid` back; see the
/// module docs). Nothing to do for Embree 3.
///
/// # Safety
/// `valid` points to the live mask of at least `i + 1` rays.
#[inline(always)]
unsafe fn report_miss(valid: *mut i32, i: usize) {
    #[cfg(embree4)]
    // SAFETY: by the caller's contract.
    unsafe {
        valid.add(i).write(0);
    }
    #[cfg(embree3)]
    let _ = (valid, i);
}

/// The primitives behind a callback's `geometryUserPtr`.
///
/// # Safety
/// `user_ptr` is the `UserPrims<T>` registered for this geometry, which the
/// `EmbreeAccel` keeps alive (and unmoved, in its `Box`) until the scene is released.
#[inline(always)]
unsafe fn prims<'a, T>(user_ptr: *mut c_void) -> Option<&'a UserPrims<T>> {
    // SAFETY: by the caller's contract; only a shared reference is formed.
    unsafe { user_ptr.cast::<UserPrims<T>>().as_ref() }
}

/// `RTCBoundsFunction`: the shape's own bounds.
pub(super) unsafe extern "C" fn bounds<T: UserShape>(args: *const sys::RTCBoundsFunctionArguments) {
    // SAFETY: Embree passes a valid argument struct for the duration of the call.
    let Some(args) = (unsafe { args.as_ref() }) else {
        return;
    };
    // SAFETY: this callback is only registered on geometries whose user data is a
    // `UserPrims<T>` (see `scene::attach_user`).
    let prim =
        unsafe { prims::<T>(args.geometryUserPtr) }.and_then(|p| p.items.get(args.primID as usize));
    // An unknown primitive gets empty bounds, which Embree skips.
    let b = prim.map_or(Aabb::EMPTY, Intersect::bounds);
    // SAFETY: `bounds_o` points to the output `RTCBounds` Embree provides for this call.
    if let Some(out) = unsafe { args.bounds_o.as_mut() } {
        out.lower_x = b.min.x;
        out.lower_y = b.min.y;
        out.lower_z = b.min.z;
        out.upper_x = b.max.x;
        out.upper_y = b.max.y;
        out.upper_z = b.max.z;
    }
}

/// `RTCIntersectFunctionN`: nearest hit with primitive `primID` for each active ray; on
/// a hit, writes `tfar`, `u`, `v`, `Ng`, `primID`, `geomID` and `instID`.
pub(super) unsafe extern "C" fn intersect<T: UserShape>(
    args: *const sys::RTCIntersectFunctionNArguments,
) {
    // SAFETY: Embree passes a valid argument struct for the duration of the call.
    let Some(args) = (unsafe { args.as_ref() }) else {
        return;
    };
    let n = args.N as usize;
    // SAFETY: registered only with `UserPrims<T>` user data (see `bounds`).
    let user = unsafe { prims::<T>(args.geometryUserPtr) };
    let prim = user.and_then(|p| p.items.get(args.primID as usize));
    let prim_id = user
        .and_then(|p| p.ids.get(args.primID as usize))
        .copied()
        .unwrap_or(args.primID);
    let packet = Packet {
        base: args.rayhit.cast(),
        n,
    };
    // SAFETY: `context` is the live query context or null.
    let inst = unsafe { instance_ids(args.context) };
    #[cfg(embree_instance_array)]
    // SAFETY: as above.
    let inst_prim = unsafe { instance_prim_ids(args.context) };
    for i in 0..n {
        // SAFETY: `valid` has `N` entries.
        if unsafe { args.valid.add(i).read() } == 0 {
            continue;
        }
        // SAFETY: `rayhit` is a live `RTCRayHitN` packet of `N` rays and `i < N`.
        let ray = unsafe { packet.ray(i) };
        match prim.and_then(|p| p.intersect(&ray)) {
            Some(h) => {
                // SAFETY: ray `i` is active; Embree expects the callback to write its
                // `tfar` and hit members on a hit. All offsets are inside the packet.
                unsafe {
                    packet.set_f32(soa::TFAR, i, h.t);
                    let hits = packet.hits();
                    hits.set_f32(soa::NG_X, i, h.ng.x);
                    hits.set_f32(soa::NG_Y, i, h.ng.y);
                    hits.set_f32(soa::NG_Z, i, h.ng.z);
                    hits.set_f32(soa::U, i, h.u);
                    hits.set_f32(soa::V, i, h.v);
                    hits.set_u32(soa::PRIM_ID, i, prim_id);
                    hits.set_u32(soa::GEOM_ID, i, args.geomID);
                    for (level, id) in inst.iter().enumerate() {
                        hits.set_u32(soa::INST_ID + level, i, *id);
                    }
                    #[cfg(embree_instance_array)]
                    for (level, id) in inst_prim.iter().enumerate() {
                        hits.set_u32(soa::INST_ID + sys::MAX_INSTANCE_LEVELS + level, i, *id);
                    }
                }
            }
            // SAFETY: `valid` has `N` entries.
            None => unsafe { report_miss(args.valid, i) },
        }
    }
}

/// `RTCOccludedFunctionN`: for each active ray that primitive `primID` occludes, sets
/// `tfar = -inf`.
pub(super) unsafe extern "C" fn occluded<T: UserShape>(
    args: *const sys::RTCOccludedFunctionNArguments,
) {
    // SAFETY: Embree passes a valid argument struct for the duration of the call.
    let Some(args) = (unsafe { args.as_ref() }) else {
        return;
    };
    let n = args.N as usize;
    // SAFETY: registered only with `UserPrims<T>` user data (see `bounds`).
    let prim =
        unsafe { prims::<T>(args.geometryUserPtr) }.and_then(|p| p.items.get(args.primID as usize));
    let packet = Packet {
        base: args.ray.cast(),
        n,
    };
    for i in 0..n {
        // SAFETY: `valid` has `N` entries.
        if unsafe { args.valid.add(i).read() } == 0 {
            continue;
        }
        // SAFETY: `ray` is a live `RTCRayN` packet of `N` rays and `i < N`.
        let ray = unsafe { packet.ray(i) };
        if prim.is_some_and(|p| p.occluded(&ray)) {
            // SAFETY: ray `i` is active; Embree reads `tfar = -inf` as "occluded".
            unsafe { packet.set_f32(soa::TFAR, i, f32::NEG_INFINITY) };
        } else {
            // SAFETY: `valid` has `N` entries.
            unsafe { report_miss(args.valid, i) };
        }
    }
}
