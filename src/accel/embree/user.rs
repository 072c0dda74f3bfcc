//! User geometry: one Embree geometry per analytic shape kind, holding all primitives of
//! that kind. Its callbacks call the same `geometry::` intersectors as the pure-Rust BVH,
//! so both backends give the same hits for every analytic kind, bit for bit.
//!
//! A panic must not unwind out of an `extern "C"` callback into Embree (Rust aborts the
//! process there). Every callback therefore runs the Rust intersector inside one
//! [`std::panic::catch_unwind`] per call (around all the lanes of a packet); a caught
//! panic is recorded (empty bounds for the bounds callback), and the panic is raised
//! again on the Rust side once Embree has returned:
//! - ray queries (`rtcIntersect1/4/8/16`, `rtcOccluded1/4/8/16`) run their traversal, and
//!   so the intersect and occluded callbacks, on the thread that calls them (Embree 3
//!   and 4 alike: the callbacks are "invoked by `rtcIntersect`-type ray queries", and
//!   only scene builds use Embree's worker threads), so the panic is kept in a
//!   thread-local slot and [`rethrow_caught`] raises it right after the query returns;
//! - the bounds callback runs during `rtcCommitScene`, on Embree's build threads, so its
//!   panic is kept in the geometry's user data and raised after the commit
//!   ([`UserGeometry::bounds_panic`]).
//!
//! The re-raised panic names the callback and the primitive kind and carries the
//! original message. Otherwise the callbacks avoid failing: no indexing that can fail
//! (`get`), no allocation, no locks. They keep no shared counters (a shared atomic costs
//! ~30% at two threads).
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

use std::cell::{Cell, RefCell};
use std::ffi::c_void;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::OnceLock;

use rayon::prelude::*;

use super::sys;
use crate::geometry::Analytic;
use crate::math::{Aabb, Ray, Vec3, next_float_up};

/// The user data of one user geometry: the scene's list of its kind, borrowed (never
/// copied), and the primitive each of Embree's `primID`s is. Lives in a `Box` owned by
/// the `EmbreeAccel`, so the pointer Embree holds stays valid until the scene has been
/// released; the accel borrows the scene for `'s`, so the list outlives it.
#[derive(Debug)]
pub(super) struct UserPrims<'s, T> {
    /// The scene's primitives of this kind.
    items: &'s [T],
    /// The indices in `items` that Embree's primitives stand for, when the geometry
    /// holds only some of the items (not the unbounded ones) or holds them in another
    /// order (in groups); `None`: Embree's primitive `k` is item `k`.
    ids: Option<Box<[u32]>>,
    /// With groups, where each starts in `ids`: Embree's primitive `k` stands for
    /// `ids[starts[k] .. starts[k + 1]]` (the last entry is `ids.len()`); empty without
    /// groups (Embree's primitive `k` is then one item).
    starts: Box<[u32]>,
    /// With groups, the items in the order of `ids`, copied so that a group's members
    /// lie together in memory (reading them through `ids` from the scene's list, where
    /// neighbours in space may lie far apart, costs a cache miss per member); empty
    /// without groups.
    grouped: Box<[T]>,
    /// The first panic caught in the bounds callback (set from Embree's build threads).
    bounds_panic: OnceLock<String>,
    /// Test hook: the bounds callback panics.
    #[cfg(test)]
    panic_in_bounds: bool,
}

impl<'s, T> UserPrims<'s, T> {
    /// The user data of the scene's list `items`, of which Embree holds those `ids`
    /// (all items in order for `None`), one item per Embree primitive or, with `ids`
    /// in Morton order and `group` > 1, in runs of at most `group` neighbours
    /// ([`group::cut_runs`](super::group::cut_runs)).
    pub(super) fn grouped(items: &'s [T], ids: Option<Box<[u32]>>, group: usize) -> Self
    where
        T: Analytic + Clone + Send + Sync,
    {
        let (grouped, starts): (Box<[T]>, Box<[u32]>) = match &ids {
            Some(ids) if group > 1 => {
                let copies = ids
                    .par_iter()
                    .filter_map(|&id| items.get(id as usize).cloned());
                let grouped: Box<[T]> = copies.collect();
                let starts = super::group::cut_runs(&grouped, group);
                (grouped, starts)
            }
            _ => (Box::default(), Box::default()),
        };
        UserPrims {
            items,
            ids,
            starts,
            grouped,
            bounds_panic: OnceLock::new(),
            #[cfg(test)]
            panic_in_bounds: inject::take(Callback::Bounds),
        }
    }

    /// The number of Embree primitives: one per group of ids.
    pub(super) fn embree_count(&self) -> usize {
        if !self.starts.is_empty() {
            return self.starts.len() - 1;
        }
        self.ids.as_ref().map_or(self.items.len(), |ids| ids.len())
    }

    /// The item with index `index` in the scene's list, and that index (the `primID` a
    /// hit reports); `None` out of range.
    #[inline(always)]
    fn item(&self, index: u32) -> Option<(&'s T, u32)> {
        Some((self.items.get(index as usize)?, index))
    }

    /// The items Embree's primitive `prim_id` stands for, in the order their tests run:
    /// one item, or the indices of a group; `None` for an id out of range.
    #[inline(always)]
    fn members(&self, prim_id: u32) -> Option<Members<'_, 's, T>> {
        let Some(ids) = &self.ids else {
            return self.item(prim_id).map(Members::One);
        };
        if self.starts.is_empty() {
            let index = *ids.get(prim_id as usize)?;
            return self.item(index).map(Members::One);
        }
        let k = prim_id as usize;
        let range = *self.starts.get(k)? as usize..*self.starts.get(k.checked_add(1)?)? as usize;
        let (members, ids) = (self.grouped.get(range.clone())?, ids.get(range)?);
        (!members.is_empty() && members.len() == ids.len()).then_some(Members::Group(members, ids))
    }

    /// The pointer registered with `rtcSetGeometryUserData`.
    pub(super) fn as_user_ptr(&self) -> *mut c_void {
        std::ptr::from_ref(self).cast_mut().cast()
    }
}

/// The items behind one Embree primitive.
enum Members<'u, 's, T> {
    /// One item and its index.
    One((&'s T, u32)),
    /// A group: copies of its items, and their indices in the scene's list.
    Group(&'u [T], &'u [u32]),
}

impl<'u, T> Members<'u, '_, T> {
    /// Call `f` with each member, in order, until it returns `true`; whether one did.
    #[inline(always)]
    fn any_item(&self, f: impl FnMut(&T) -> bool) -> bool {
        match self {
            Members::One((item, _)) => std::iter::once(*item).any(f),
            Members::Group(items, _) => items.iter().any(f),
        }
    }
}

/// The user data of a user geometry as the scene keeps it alive, whatever its kind.
pub(super) trait UserGeometry: Send + Sync + std::fmt::Debug {
    /// The message of a panic caught in the bounds callback during the last commit
    /// (naming the callback and the kind), if there was one.
    fn bounds_panic(&self) -> Option<String>;
    /// Bytes of the index the callbacks read besides the scene's primitives (emray's
    /// memory, which Embree's memory monitor does not see).
    fn bytes(&self) -> usize;
}

impl<T: Analytic> UserGeometry for UserPrims<'_, T> {
    fn bytes(&self) -> usize {
        let ids = self
            .ids
            .as_ref()
            .map_or(0, |ids| std::mem::size_of_val(&**ids));
        ids + std::mem::size_of_val(&*self.grouped) + std::mem::size_of_val(&*self.starts)
    }

    fn bounds_panic(&self) -> Option<String> {
        self.bounds_panic
            .get()
            .map(|m| caught_message(Callback::Bounds, T::KIND.name(), m))
    }
}

/// The callbacks, to name them in messages (and, in tests, to make one panic).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Callback {
    /// `RTCBoundsFunction`.
    Bounds,
    /// `RTCIntersectFunctionN`.
    Intersect,
    /// `RTCOccludedFunctionN`.
    Occluded,
}

impl Callback {
    fn name(self) -> &'static str {
        match self {
            Callback::Bounds => "bounds",
            Callback::Intersect => "intersect",
            Callback::Occluded => "occluded",
        }
    }
}

thread_local! {
    /// Whether a callback of the current query on this thread caught a panic.
    static PENDING: Cell<bool> = const { Cell::new(false) };
    /// The message of the first panic caught since the last [`rethrow_caught`].
    static CAUGHT: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// The text of a panic's payload (`panic!` gives a `&str` or a `String`).
fn payload_text(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "(a panic without a message)".to_string()
    }
}

fn caught_message(callback: Callback, kind: &str, message: &str) -> String {
    format!(
        "the Embree {} callback of the {kind} panicked: {message}",
        callback.name()
    )
}

/// Keep the first panic caught in a query's callback on this thread (never unwinds).
#[cold]
#[inline(never)]
fn record_query_panic(callback: Callback, kind: &str, payload: &(dyn std::any::Any + Send)) {
    if !PENDING.get() {
        let message = caught_message(callback, kind, &payload_text(payload));
        CAUGHT.set(Some(message));
        PENDING.set(true);
    }
}

/// Raise, on the Rust side, a panic that a callback of the query that just returned on
/// this thread caught (call right after every `rtcIntersect*`/`rtcOccluded*`).
#[inline(always)]
pub(super) fn rethrow_caught() {
    if PENDING.get() {
        rethrow_pending();
    }
}

#[cold]
#[inline(never)]
fn rethrow_pending() -> ! {
    PENDING.set(false);
    let message = CAUGHT.take().unwrap_or_default();
    panic!("{message}");
}

/// Test hooks: make the next callback of one kind panic.
#[cfg(test)]
pub(super) mod inject {
    use super::Callback;
    use std::cell::Cell;

    thread_local! {
        static NEXT: Cell<Option<Callback>> = const { Cell::new(None) };
    }

    /// Make the next `callback` on this thread panic with "injected panic"; for
    /// [`Callback::Bounds`], the bounds callbacks of the next user geometry attached on
    /// this thread (they run on Embree's build threads).
    pub(in crate::accel::embree) fn panic_next(callback: Callback) {
        NEXT.set(Some(callback));
    }

    /// Whether the next `callback` should panic (consumes the request).
    pub(super) fn take(callback: Callback) -> bool {
        let hit = NEXT.get() == Some(callback);
        if hit {
            NEXT.set(None);
        }
        hit
    }
}

/// Test hook: panic when [`inject`] asks `callback` to.
#[cfg(test)]
#[inline(always)]
fn maybe_injected_panic(callback: Callback) {
    if inject::take(callback) {
        panic!("injected panic");
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

    /// Whether ray `i` is `occluded` (tested on the ray in our terms); if it is, the
    /// ray is marked so (`tfar = -inf`, which Embree reads as "occluded").
    ///
    /// # Safety
    /// As [`Packet::ray`].
    #[inline(always)]
    unsafe fn occlude_if(self, i: usize, occluded: impl FnOnce(&Ray) -> bool) -> bool {
        // SAFETY: by the caller's contract.
        let ray = unsafe { self.ray(i) };
        #[cfg(test)]
        maybe_injected_panic(Callback::Occluded);
        let hit = occluded(&ray);
        if hit {
            // SAFETY: as above; `tfar` is a member of every ray.
            unsafe { self.set_f32(soa::TFAR, i, f32::NEG_INFINITY) };
        }
        hit
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
unsafe fn prims<'a, T>(user_ptr: *mut c_void) -> Option<&'a UserPrims<'a, T>> {
    // SAFETY: by the caller's contract; only a shared reference is formed.
    unsafe { user_ptr.cast::<UserPrims<'a, T>>().as_ref() }
}

/// `RTCBoundsFunction`: the shape's own bounds, or the union of a group's (empty,
/// which Embree skips, for an unknown primitive or when a shape's `bounds` panics).
pub(super) unsafe extern "C" fn bounds<T: Analytic>(args: *const sys::RTCBoundsFunctionArguments) {
    // SAFETY: Embree passes a valid argument struct for the duration of the call.
    let Some(args) = (unsafe { args.as_ref() }) else {
        return;
    };
    // SAFETY: this callback is only registered on geometries whose user data is a
    // `UserPrims<T>` (see `scene::attach_user`).
    let user = unsafe { prims::<T>(args.geometryUserPtr) };
    let members = user.and_then(|p| p.members(args.primID));
    let b = match catch_unwind(AssertUnwindSafe(|| {
        #[cfg(test)]
        if user.is_some_and(|u| u.panic_in_bounds) {
            panic!("injected panic");
        }
        let mut b = Aabb::EMPTY;
        if let Some(members) = &members {
            members.any_item(|prim| {
                b = b.union(&prim.bounds());
                false
            });
        }
        b
    })) {
        Ok(b) => b,
        Err(payload) => {
            if let Some(user) = user {
                let _ = user.bounds_panic.set(payload_text(&*payload));
            }
            Aabb::EMPTY
        }
    };
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

/// The hit ray `i` of an `RTCHitN` packet holds so far, as `(geomID, primID, instID[0])`,
/// or `None` before any.
///
/// # Safety
/// `hits` is the hit part of a live `RTCRayHitN` packet and `i < n`.
#[inline(always)]
unsafe fn current_hit(hits: Packet, i: usize) -> Option<(u32, u32, u32)> {
    // SAFETY: by the caller's contract, the hit members exist for ray `i`.
    let word = |field| unsafe { hits.word(field, i).read() };
    let geom = word(soa::GEOM_ID);
    (geom != sys::INVALID_GEOMETRY_ID).then(|| (geom, word(soa::PRIM_ID), word(soa::INST_ID)))
}

/// Mark every active ray of a call as missed: the callback has no primitive to test
/// (an id Embree should never pass).
///
/// # Safety
/// `valid` points to the live mask of at least `n` rays.
#[cold]
unsafe fn report_all_missed(valid: *mut i32, n: usize) {
    for i in 0..n {
        // SAFETY: by the caller's contract.
        unsafe { report_miss(valid, i) };
    }
}

/// Call `answer` with each active ray `i` of a call's `n`, which says whether the
/// ray hit; a ray that did not is reported missed.
///
/// # Safety
/// `valid` points to the live mask of at least `n` rays.
#[inline(always)]
unsafe fn answer_lanes(valid: *mut i32, n: usize, mut answer: impl FnMut(usize) -> bool) {
    for i in 0..n {
        // SAFETY: by the caller's contract.
        if unsafe { valid.add(i).read() } == 0 {
            continue;
        }
        if !answer(i) {
            // SAFETY: as above.
            unsafe { report_miss(valid, i) };
        }
    }
}

/// Whether any of a group's members occludes `ray`. Kept out of line, so that the
/// shape's test is inlined where a primitive stands alone (the common case) rather
/// than called there.
#[inline(never)]
fn any_occludes<T: Analytic>(prims: &[T], ray: &Ray) -> bool {
    prims.iter().any(|prim| prim.occluded(ray))
}

/// `RTCIntersectFunctionN`: nearest hit with primitive `primID` (each member of its
/// group in turn) for each active ray, or one at the current `tfar` that wins the tie
/// with the hit there; on a hit, writes `tfar`, `u`, `v`, `Ng`, `primID` (the member's
/// index in the scene's list), `geomID` and `instID`.
///
/// Packet queries call it with all `N` lanes of a packet and a mask whenever any lane
/// reaches the primitive, so the per-call work (the primitive, its id, the instance
/// stack, the unwind guard) is done once and the per-lane work is the test alone. A
/// panic leaves the lanes after it unanswered: the query's result is thrown away when
/// [`rethrow_caught`] raises the panic.
pub(super) unsafe extern "C" fn intersect<T: Analytic>(
    args: *const sys::RTCIntersectFunctionNArguments,
) {
    // SAFETY: Embree passes a valid argument struct for the duration of the call.
    let Some(args) = (unsafe { args.as_ref() }) else {
        return;
    };
    let n = args.N as usize;
    // SAFETY: registered only with `UserPrims<T>` user data (see `bounds`).
    let user = unsafe { prims::<T>(args.geometryUserPtr) };
    let Some(members) = user.and_then(|p| p.members(args.primID)) else {
        // SAFETY: `valid` has `N` entries.
        unsafe { report_all_missed(args.valid, n) };
        return;
    };
    let lane = Lane {
        packet: Packet {
            base: args.rayhit.cast(),
            n,
        },
        geom_id: args.geomID,
        // SAFETY: `context` is the live query context or null.
        inst: unsafe { instance_ids(args.context) },
        #[cfg(embree_instance_array)]
        // SAFETY: as above.
        inst_prim: unsafe { instance_prim_ids(args.context) },
    };
    // The kind of members is matched once per call, not once per lane: a primitive
    // alone is the common case and its loop stays free of the group's.
    let lanes = || match members {
        // SAFETY: `valid` has `N` entries, and `answer_lanes` passes active rays of the
        // live packet only.
        Members::One((prim, id)) => unsafe {
            answer_lanes(args.valid, n, |i| lane.test(i, prim, || id))
        },
        // SAFETY: as above.
        Members::Group(prims, ids) => unsafe {
            answer_lanes(args.valid, n, |i| {
                let mut hit = false;
                for (prim, &id) in prims.iter().zip(ids) {
                    hit |= lane.test(i, prim, || id);
                }
                hit
            })
        },
    };
    if let Err(payload) = catch_unwind(AssertUnwindSafe(lanes)) {
        record_query_panic(Callback::Intersect, T::KIND.name(), &*payload);
    }
}

/// What the intersect callback writes a hit with, besides the hit itself.
struct Lane {
    /// The `RTCRayHitN` packet.
    packet: Packet,
    geom_id: u32,
    inst: [u32; sys::MAX_INSTANCE_LEVELS],
    #[cfg(embree_instance_array)]
    inst_prim: [u32; sys::MAX_INSTANCE_LEVELS],
}

impl Lane {
    /// Test ray `i` against `prim` (item `prim_id()` of the list), from the ray's state
    /// in the packet (an earlier member of a group may have shortened it); on a nearer
    /// hit, or one at `tfar` that wins the tie with the hit there, write it and return
    /// `true`.
    ///
    /// # Safety
    /// `packet` is a live `RTCRayHitN` packet and ray `i < n` is active.
    #[inline(always)]
    unsafe fn test<T: Analytic>(&self, i: usize, prim: &T, prim_id: impl Fn() -> u32) -> bool {
        let packet = self.packet;
        // SAFETY: by the caller's contract.
        let mut ray = unsafe { packet.ray(i) };
        // SAFETY: as above; the hit members follow the ray's.
        let current = unsafe { current_hit(packet.hits(), i) };
        // A hit at `tfar` already: look up to and including `tfar` for a coincident
        // primitive that wins the tie (`Hit::wins_tie_with`), as the BVH does.
        let tfar = ray.tmax;
        if current.is_some() {
            ray.tmax = next_float_up(tfar);
        }
        #[cfg(test)]
        maybe_injected_panic(Callback::Intersect);
        let hit = prim.intersect(&ray).filter(|h| {
            h.t < tfar
                || current.is_some_and(|(geom, prim, level)| {
                    h.t == tfar && level == self.inst[0] && (self.geom_id, prim_id()) < (geom, prim)
                })
        });
        let Some(h) = hit else {
            return false;
        };
        // SAFETY: ray `i` is active; Embree expects the callback to write its `tfar` and
        // hit members on a hit. All offsets are inside the packet.
        unsafe {
            packet.set_f32(soa::TFAR, i, h.t);
            let hits = packet.hits();
            hits.set_f32(soa::NG_X, i, h.ng.x);
            hits.set_f32(soa::NG_Y, i, h.ng.y);
            hits.set_f32(soa::NG_Z, i, h.ng.z);
            hits.set_f32(soa::U, i, h.u);
            hits.set_f32(soa::V, i, h.v);
            hits.set_u32(soa::PRIM_ID, i, prim_id());
            hits.set_u32(soa::GEOM_ID, i, self.geom_id);
            for (level, id) in self.inst.iter().enumerate() {
                hits.set_u32(soa::INST_ID + level, i, *id);
            }
            #[cfg(embree_instance_array)]
            for (level, id) in self.inst_prim.iter().enumerate() {
                hits.set_u32(soa::INST_ID + sys::MAX_INSTANCE_LEVELS + level, i, *id);
            }
        }
        true
    }
}

/// `RTCOccludedFunctionN`: for each active ray that primitive `primID` (a member of its
/// group) occludes, sets `tfar = -inf` (per-call work done once, as in [`intersect`]).
pub(super) unsafe extern "C" fn occluded<T: Analytic>(
    args: *const sys::RTCOccludedFunctionNArguments,
) {
    // SAFETY: Embree passes a valid argument struct for the duration of the call.
    let Some(args) = (unsafe { args.as_ref() }) else {
        return;
    };
    let n = args.N as usize;
    // SAFETY: registered only with `UserPrims<T>` user data (see `bounds`).
    let user = unsafe { prims::<T>(args.geometryUserPtr) };
    let Some(members) = user.and_then(|p| p.members(args.primID)) else {
        // SAFETY: `valid` has `N` entries.
        unsafe { report_all_missed(args.valid, n) };
        return;
    };
    let packet = Packet {
        base: args.ray.cast(),
        n,
    };
    let lanes = || match members {
        // SAFETY: `valid` has `N` entries, and `answer_lanes` passes active rays of the
        // live `RTCRayN` packet only.
        Members::One((prim, _)) => unsafe {
            answer_lanes(args.valid, n, |i| {
                packet.occlude_if(i, |ray| prim.occluded(ray))
            })
        },
        // SAFETY: as above.
        Members::Group(prims, _) => unsafe {
            answer_lanes(args.valid, n, |i| {
                packet.occlude_if(i, |ray| any_occludes(prims, ray))
            })
        },
    };
    if let Err(payload) = catch_unwind(AssertUnwindSafe(lanes)) {
        record_query_panic(Callback::Occluded, T::KIND.name(), &*payload);
    }
}
