//! Scene building (triangles natively, one user geometry per analytic kind) and the
//! committed, immutable scene the ray queries run on.

use super::device::Device;
use super::error::EmbreeError;
use super::group::morton_order;
use super::sys;
use super::user::{self, UserGeometry, UserPrims, rethrow_caught};
use crate::accel::unbounded::{Unbounded, is_unbounded};
use crate::accel::{Hit, NO_INSTANCE, add_kind};
use crate::geometry::{Analytic, Kind, Triangle};
use crate::math::{Ray, Vec3, Xform};
use crate::scene::{Geometry as SceneGeometry, KindVisitor, Prims};

/// An owned geometry handle during the build; released once attached (the scene keeps
/// its own reference).
struct Geometry(sys::RTCGeometry);

impl Drop for Geometry {
    fn drop(&mut self) {
        // SAFETY: `self.0` is a live geometry created by `rtcNewGeometry`; this drops our
        // reference only.
        unsafe { sys::rtcReleaseGeometry(self.0) }
    }
}

impl Geometry {
    fn new(
        device: &Device,
        kind: sys::RTCGeometryType,
        what: &str,
    ) -> Result<Geometry, EmbreeError> {
        // SAFETY: `device` is live; a bad type only sets an error and returns null.
        let raw = unsafe { sys::rtcNewGeometry(device.raw(), kind) };
        if raw.is_null() {
            device.check(format!("rtcNewGeometry({what})"))?;
            return Err(EmbreeError::emray(
                format!("rtcNewGeometry({what})"),
                "Embree returned no geometry",
            ));
        }
        Ok(Geometry(raw))
    }

    /// Commit and attach under geometry id `id` (our `Kind` discriminant, or
    /// `INSTANCE_BASE + i` for instance `i`).
    fn commit_and_attach(
        self,
        device: &Device,
        scene: &Level<'_>,
        id: u32,
        what: &str,
    ) -> Result<(), EmbreeError> {
        // SAFETY: both handles are live and belong to the same device; the id is unused
        // in this scene (one geometry per kind, one per instance).
        unsafe {
            sys::rtcCommitGeometry(self.0);
            sys::rtcAttachGeometryByID(scene.raw, self.0, id);
        }
        device.check(format!("attaching the {what} geometry"))
    }
}

/// Geometry id of the first instance in the top-level scene (kinds use 0..).
const INSTANCE_BASE: u32 = 64;

/// One Embree scene, the top level or an instanced object, owning the user data its
/// callbacks read (which borrows the scene's primitives for `'s`).
#[derive(Debug)]
struct Level<'s> {
    raw: sys::RTCScene,
    /// Dropped after `Drop::drop` has released `raw`, so no callback can outlive it.
    user: UserData<'s>,
}

impl Drop for Level<'_> {
    fn drop(&mut self) {
        // SAFETY: `self.raw` is a live scene; no query can be running (queries borrow
        // the `CommittedScene`). Releasing it releases the geometries it holds (instance
        // geometries hold their own reference to an object's scene); `self.user` is
        // freed only after this.
        unsafe { sys::rtcReleaseScene(self.raw) }
    }
}

/// The user data of the analytic geometries, one `UserPrims<P>` per kind attached
/// (boxed: Embree holds their addresses). Kept alive for the callbacks; read from Rust
/// only for a panic caught in a bounds callback.
#[derive(Debug, Default)]
struct UserData<'s> {
    kinds: Vec<Box<dyn UserGeometry + 's>>,
}

/// A committed Embree scene: the top level (with one instance geometry per instance),
/// the objects' scenes, and the unbounded primitives. Immutable after
/// [`CommittedScene::build`]; queried from any number of threads.
#[derive(Debug)]
pub(super) struct CommittedScene<'s> {
    // Fields drop in declaration order: the top level first, so the instance
    // geometries let go of the objects' scenes before those are released.
    top: Level<'s>,
    objects: Vec<Level<'s>>,
    /// What Embree cannot hold (infinite bounds), intersected in Rust before each query.
    unbounded: Unbounded,
    /// The kinds attached, with counts (see [`crate::accel::AccelStats::kinds`]).
    pub(super) kinds: Vec<(Kind, usize)>,
}

// SAFETY: the handles refer to Embree's reference-counted scene objects; they are only
// mutated inside `build`, before they are shared.
unsafe impl Send for CommittedScene<'_> {}
// SAFETY: after `rtcCommitScene` the scenes are never modified, and Embree documents
// `rtcIntersect1`/`rtcOccluded1` on a committed scene as safe to call from many threads
// at once. The primitives the callbacks read are immutable and `Sync` (`Analytic`
// requires it); the only state they write is the bounds callbacks' panic slot, a
// `OnceLock`, and only during the commit.
unsafe impl Sync for CommittedScene<'_> {}

/// The flags of every scene emray commits. Robust traversal takes no arithmetic
/// shortcuts that can miss rays through shared edges and vertices; a compact scene
/// takes less memory and builds faster, and traverses somewhat slower.
fn scene_flags(robust: bool, compact: bool) -> sys::RTCSceneFlags {
    let mut flags = sys::RTCSceneFlags::RTC_SCENE_FLAG_NONE;
    if robust {
        flags |= sys::RTCSceneFlags::RTC_SCENE_FLAG_ROBUST;
    }
    if compact {
        flags |= sys::RTCSceneFlags::RTC_SCENE_FLAG_COMPACT;
    }
    flags
}

impl<'s> Level<'s> {
    /// A new, empty scene with `flags`.
    fn new(device: &Device, flags: sys::RTCSceneFlags) -> Result<Level<'s>, EmbreeError> {
        // SAFETY: `device` is live.
        let raw = unsafe { sys::rtcNewScene(device.raw()) };
        if raw.is_null() {
            device.check("rtcNewScene")?;
            return Err(EmbreeError::emray(
                "rtcNewScene",
                "Embree returned no scene",
            ));
        }
        let level = Level {
            raw,
            user: UserData::default(),
        };
        // SAFETY: `raw` is a live, uncommitted scene; `flags` are Embree's scene flags.
        unsafe { sys::rtcSetSceneFlags(raw, flags) };
        device.check("rtcSetSceneFlags")?;
        Ok(level)
    }

    /// Attach every bounded primitive of `geometry`, one geometry per kind present,
    /// `group` analytic primitives per Embree primitive (see `group`), adding to
    /// `kinds` the count of each kind (the unbounded ones included: the [`Unbounded`]
    /// list holds them).
    fn attach_geometry(
        &mut self,
        device: &Device,
        geometry: &'s SceneGeometry,
        group: usize,
        kinds: &mut Vec<(Kind, usize)>,
    ) -> Result<(), EmbreeError> {
        if !geometry.triangles.is_empty() {
            attach_triangles(device, self, &geometry.triangles.items)?;
            add_kind(kinds, Kind::Triangle, geometry.triangles.len());
        }
        let mut attach = AttachUser {
            device,
            level: self,
            group,
            kinds,
            user: Vec::new(),
        };
        geometry.try_visit_all(&mut attach)?;
        self.user.kinds = attach.user;
        Ok(())
    }

    /// Commit after every geometry is attached, building at `quality`.
    fn commit(&self, device: &Device, quality: sys::RTCBuildQuality) -> Result<(), EmbreeError> {
        // SAFETY: `raw` is a live, uncommitted scene; any quality constant is valid.
        unsafe { sys::rtcSetSceneBuildQuality(self.raw, quality) };
        device.check("rtcSetSceneBuildQuality")?;
        // SAFETY: `raw` is live; every attached geometry is committed and its user data
        // is boxed in `self.user` (or an object level's), which lives as long as the
        // scene.
        unsafe { sys::rtcCommitScene(self.raw) };
        if let Some(message) = self.user.kinds.iter().find_map(|u| u.bounds_panic()) {
            panic!("{message}");
        }
        device.check("rtcCommitScene")
    }
}

/// Attaches one user geometry per kind visited (the bounded primitives of the list),
/// keeping its user data, which borrows the list, in `user`.
struct AttachUser<'a, 's> {
    device: &'a Device,
    level: &'a Level<'s>,
    /// Primitives per Embree primitive.
    group: usize,
    kinds: &'a mut Vec<(Kind, usize)>,
    user: Vec<Box<dyn UserGeometry + 's>>,
}

impl<'s> KindVisitor<'s> for AttachUser<'_, 's> {
    type Output = Result<(), EmbreeError>;

    fn visit<P: Analytic>(&mut self, list: &'s Prims<P>) -> Result<(), EmbreeError> {
        add_kind(self.kinds, P::KIND, list.len());
        let items = &list.items[..];
        let ids = bounded_ids(items);
        let held = ids.as_ref().map_or(items.len(), |ids| ids.len());
        let (ids, group) = if self.group > 1 && held > self.group {
            let start = std::time::Instant::now();
            let order = morton_order(items, ids);
            log::info!(
                "ordered {held} {} for groups of at most {} in {:.0?}",
                P::KIND.name(),
                self.group,
                start.elapsed()
            );
            (Some(order), self.group)
        } else {
            (ids, 1)
        };
        if let Some(data) = attach_user(self.device, self.level, items, ids, group)? {
            self.user.push(data);
        }
        Ok(())
    }
}

/// The indices of the bounded primitives of `items` when some are unbounded (Embree
/// cannot hold those); `None` when all are bounded.
fn bounded_ids<P: Analytic>(items: &[P]) -> Option<Box<[u32]>> {
    if !items.iter().any(|p| is_unbounded(&p.bounds())) {
        return None;
    }
    let bounded = (0u32..)
        .zip(items)
        .filter(|(_, p)| !is_unbounded(&p.bounds()));
    Some(bounded.map(|(i, _)| i).collect())
}

impl<'s> CommittedScene<'s> {
    /// Bytes of what the scene keeps on emray's side for Embree: the user geometries'
    /// indices of bounded primitives (when a list has unbounded ones) and the
    /// unbounded primitives. The primitives themselves are the scene's.
    pub(super) fn rust_bytes(&self) -> usize {
        let user = |level: &Level<'_>| level.user.kinds.iter().map(|k| k.bytes()).sum::<usize>();
        user(&self.top)
            + self.objects.iter().map(user).sum::<usize>()
            + self.unbounded.memory_bytes()
    }

    /// Build and commit the scene of `scene`'s primitives at build quality `quality`,
    /// every level with `RTC_SCENE_FLAG_ROBUST` if `robust` and `RTC_SCENE_FLAG_COMPACT`
    /// if `compact`, `group` analytic primitives per Embree primitive.
    pub(super) fn build(
        device: &Device,
        scene: &'s crate::scene::Scene,
        quality: crate::accel::EmbreeQuality,
        robust: bool,
        compact: bool,
        group: usize,
    ) -> Result<CommittedScene<'s>, EmbreeError> {
        use crate::accel::EmbreeQuality as Q;
        let quality = match quality {
            Q::Low => sys::RTCBuildQuality::RTC_BUILD_QUALITY_LOW,
            Q::Medium => sys::RTCBuildQuality::RTC_BUILD_QUALITY_MEDIUM,
            Q::High => sys::RTCBuildQuality::RTC_BUILD_QUALITY_HIGH,
        };
        let flags = scene_flags(robust, compact);
        let mut kinds = Vec::new();
        let mut objects = Vec::with_capacity(scene.objects.len());
        for object in &scene.objects {
            let mut level = Level::new(device, flags)?;
            level.attach_geometry(device, object, group, &mut kinds)?;
            level.commit(device, quality)?;
            objects.push(level);
        }
        let mut top = Level::new(device, flags)?;
        top.attach_geometry(device, &scene.geometry, group, &mut kinds)?;
        for (i, inst) in (0u32..).zip(&scene.instances) {
            let object = inst.object as usize;
            let id = INSTANCE_BASE.checked_add(i).ok_or_else(|| {
                EmbreeError::emray("building the instances", "too many instances")
            })?;
            attach_instance(device, &top, &objects[object], &inst.xform, id)?;
        }
        top.commit(device, quality)?;
        Ok(CommittedScene {
            top,
            objects,
            unbounded: Unbounded::new(scene),
            kinds,
        })
    }

    /// The nearest hit with `t` in `[max(ray.tmin, 0), ray.tmax]` (Embree requires
    /// `tnear >= 0`).
    #[inline]
    pub(super) fn intersect(&self, ray: &Ray) -> Option<Hit> {
        if !ray.is_traceable() {
            return None;
        }
        if self.unbounded.is_empty() {
            return self.intersect_embree(ray);
        }
        // The unbounded primitives first, from `tnear` as Embree would, then Embree up
        // to the nearest of them.
        let tnear = ray.tmin.max(0.0);
        let near = self.unbounded.nearest(&Ray {
            tmin: tnear,
            ..*ray
        });
        match near {
            None => self.intersect_embree(ray),
            Some(h) => self
                .intersect_embree(&Ray { tmax: h.t, ..*ray })
                .or(Some(h)),
        }
    }

    /// Whether anything lies in the ray's interval (any hit).
    // Always inlined, as it was before the panic check after the query: shadow rays are
    // the most frequent query, and the call costs more than the check.
    #[inline(always)]
    pub(super) fn occluded(&self, ray: &Ray) -> bool {
        if !ray.is_traceable() {
            return false;
        }
        if !self.unbounded.is_empty() {
            let tnear = ray.tmin.max(0.0);
            if self.unbounded.any(&Ray {
                tmin: tnear,
                ..*ray
            }) {
                return true;
            }
        }
        self.occluded_embree(ray)
    }

    /// The nearest hit with `t` in `[max(ray.tmin, 0), ray.tmax]` (Embree requires
    /// `tnear >= 0`).
    #[inline]
    fn intersect_embree(&self, ray: &Ray) -> Option<Hit> {
        let tnear = embree_tnear(ray)?;
        let mut rayhit = sys::RTCRayHit {
            ray: rtc_ray(ray, tnear),
            hit: empty_hit(),
        };
        query::intersect(self.top.raw, &mut rayhit);
        rethrow_caught();
        let hit = &rayhit.hit;
        if hit.geomID == sys::INVALID_GEOMETRY_ID {
            return None;
        }
        Some(Hit {
            t: rayhit.ray.tfar,
            geom_id: hit.geomID,
            prim_id: hit.primID,
            u: hit.u,
            v: hit.v,
            ng: Vec3::new(hit.Ng_x, hit.Ng_y, hit.Ng_z),
            inst_id: match hit.instID[0] {
                sys::INVALID_GEOMETRY_ID => NO_INSTANCE,
                id => id - INSTANCE_BASE,
            },
        })
    }

    #[inline(always)]
    fn occluded_embree(&self, ray: &Ray) -> bool {
        let Some(tnear) = embree_tnear(ray) else {
            return false;
        };
        let mut r = rtc_ray(ray, tnear);
        query::occluded(self.top.raw, &mut r);
        rethrow_caught();
        r.tfar == f32::NEG_INFINITY
    }
}

impl CommittedScene<'_> {
    /// The nearest hits of `rays` (`hits[i]` for `rays[i]`), cast as packets of `width`
    /// (4, 8 or 16) rays flagged coherent; any other width, or a scene with unbounded
    /// primitives (tested outside Embree, one ray at a time), casts single rays.
    pub(super) fn intersect_packets(&self, rays: &[Ray], hits: &mut [Option<Hit>], width: usize) {
        let cast: fn(sys::RTCScene, &[Ray], &mut [Option<Hit>]) = match width {
            4 if self.unbounded.is_empty() => packet4,
            8 if self.unbounded.is_empty() => packet8,
            16 if self.unbounded.is_empty() => packet16,
            _ => {
                for (ray, hit) in rays.iter().zip(hits.iter_mut()) {
                    *hit = self.intersect(ray);
                }
                return;
            }
        };
        for (r, h) in rays.chunks(width).zip(hits.chunks_mut(width)) {
            cast(self.top.raw, r, h);
        }
    }

    /// Whether each of `rays` is occluded (`occluded[i]` for `rays[i]`), cast as
    /// packets of `width` (4, 8 or 16) rays flagged coherent; any other width, or a
    /// scene with unbounded primitives, casts single rays.
    pub(super) fn occluded_packets(&self, rays: &[Ray], occluded: &mut [bool], width: usize) {
        let cast: fn(sys::RTCScene, &[Ray], &mut [bool]) = match width {
            4 if self.unbounded.is_empty() => shadow4,
            8 if self.unbounded.is_empty() => shadow8,
            16 if self.unbounded.is_empty() => shadow16,
            _ => {
                for (ray, o) in rays.iter().zip(occluded.iter_mut()) {
                    *o = self.occluded(ray);
                }
                return;
            }
        };
        for (r, o) in rays.chunks(width).zip(occluded.chunks_mut(width)) {
            cast(self.top.raw, r, o);
        }
    }
}

/// The `tnear` Embree is given for `ray`, `max(tmin, 0)` (Embree requires `tnear >= 0`),
/// or `None` for a ray that must not reach Embree: one that is not
/// [traceable](Ray::is_traceable) (Embree's traversal asserts its origin and direction
/// are finite and below `FLT_LARGE`) or whose interval is empty. Such a ray hits
/// nothing. Every ray handed to Embree passes through here.
#[inline(always)]
fn embree_tnear(ray: &Ray) -> Option<f32> {
    let tnear = ray.tmin.max(0.0);
    (ray.is_traceable() && ray.tmax >= tnear).then_some(tnear)
}

/// The valid mask of a packet of N rays (-1: the ray is cast, 0: it is not). Embree
/// loads it as one vector, so it must be aligned as the packet is (16, 32 or 64 bytes
/// for 4, 8 or 16 rays); 64 serves them all.
#[repr(C, align(64))]
struct ValidMask<const N: usize>([i32; N]);

const _: () = assert!(std::mem::align_of::<ValidMask<4>>() == 64);

/// Lane `$i` of ray packet `$r` (an `RTCRayN`) set to `$ray` from `$tnear`: mask all ones,
/// no flags, time 0, as [`rtc_ray`] sets a single ray.
macro_rules! set_lane {
    ($r:expr, $i:expr, $ray:expr, $tnear:expr) => {{
        let (r, i, ray) = ($r, $i, $ray);
        (r.org_x[i], r.org_y[i], r.org_z[i]) = (ray.org.x, ray.org.y, ray.org.z);
        (r.dir_x[i], r.dir_y[i], r.dir_z[i]) = (ray.dir.x, ray.dir.y, ray.dir.z);
        (r.tnear[i], r.tfar[i], r.time[i]) = ($tnear, ray.tmax, 0.0);
        (r.mask[i], r.id[i], r.flags[i]) = (u32::MAX, 0, 0);
    }};
}

/// `packetN(scene, rays, hits)`: up to N rays through one `rtcIntersectN` call, with the
/// same conventions as the single-ray query (see [`embree_tnear`]; a ray it refuses is
/// left out of the packet and misses).
macro_rules! packet_query {
    ($name:ident, $n:literal, $ty:ident, $query:ident) => {
        fn $name(scene: sys::RTCScene, rays: &[Ray], hits: &mut [Option<Hit>]) {
            let mut p = sys::$ty::default();
            let mut valid = ValidMask([0i32; $n]);
            for (i, ray) in rays.iter().enumerate().take($n) {
                let Some(tnear) = embree_tnear(ray) else {
                    continue;
                };
                valid.0[i] = -1;
                set_lane!(&mut p.ray, i, ray, tnear);
                let h = &mut p.hit;
                h.geomID[i] = sys::INVALID_GEOMETRY_ID;
                h.primID[i] = sys::INVALID_GEOMETRY_ID;
                for level in &mut h.instID {
                    level[i] = sys::INVALID_GEOMETRY_ID;
                }
                #[cfg(embree_instance_array)]
                for level in &mut h.instPrimID {
                    level[i] = sys::INVALID_GEOMETRY_ID;
                }
            }
            query::$query(&valid, scene, &mut p);
            rethrow_caught();
            for (i, out) in hits.iter_mut().enumerate().take($n) {
                let h = &p.hit;
                *out = (valid.0[i] != 0 && h.geomID[i] != sys::INVALID_GEOMETRY_ID).then(|| Hit {
                    t: p.ray.tfar[i],
                    geom_id: h.geomID[i],
                    prim_id: h.primID[i],
                    u: h.u[i],
                    v: h.v[i],
                    ng: Vec3::new(h.Ng_x[i], h.Ng_y[i], h.Ng_z[i]),
                    inst_id: match h.instID[0][i] {
                        sys::INVALID_GEOMETRY_ID => NO_INSTANCE,
                        id => id - INSTANCE_BASE,
                    },
                });
            }
        }
    };
}

packet_query!(packet4, 4, RTCRayHit4, intersect4);
packet_query!(packet8, 8, RTCRayHit8, intersect8);
packet_query!(packet16, 16, RTCRayHit16, intersect16);

/// `shadowN(scene, rays, occluded)`: up to N rays through one `rtcOccludedN` call, with
/// the same conventions as the single-ray query (see [`embree_tnear`]; a ray it refuses
/// is left out of the packet and is not occluded).
macro_rules! shadow_query {
    ($name:ident, $n:literal, $ty:ident, $query:ident) => {
        fn $name(scene: sys::RTCScene, rays: &[Ray], occluded: &mut [bool]) {
            let mut r = sys::$ty::default();
            let mut valid = ValidMask([0i32; $n]);
            for (i, ray) in rays.iter().enumerate().take($n) {
                let Some(tnear) = embree_tnear(ray) else {
                    continue;
                };
                valid.0[i] = -1;
                set_lane!(&mut r, i, ray, tnear);
            }
            query::$query(&valid, scene, &mut r);
            rethrow_caught();
            for (i, out) in occluded.iter_mut().enumerate().take($n) {
                *out = valid.0[i] != 0 && r.tfar[i] == f32::NEG_INFINITY;
            }
        }
    };
}

shadow_query!(shadow4, 4, RTCRay4, occluded4);
shadow_query!(shadow8, 8, RTCRay8, occluded8);
shadow_query!(shadow16, 16, RTCRay16, occluded16);

// `rtcIntersect1` requires a 16-byte aligned `RTCRayHit`; bindgen carries the header's
// `RTC_ALIGN(16)` over, so every `RTCRayHit` value on the stack is aligned.
const _: () = assert!(std::mem::align_of::<sys::RTCRayHit>() == 16);
const _: () = assert!(std::mem::align_of::<sys::RTCRay>() == 16);

/// Our ray as an `RTCRay`: mask all ones (a zero mask hits nothing), no flags, time 0.
#[inline(always)]
fn rtc_ray(ray: &Ray, tnear: f32) -> sys::RTCRay {
    sys::RTCRay {
        org_x: ray.org.x,
        org_y: ray.org.y,
        org_z: ray.org.z,
        tnear,
        dir_x: ray.dir.x,
        dir_y: ray.dir.y,
        dir_z: ray.dir.z,
        time: 0.0,
        tfar: ray.tmax,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

/// A hit record that says "no hit": all ids `RTC_INVALID_GEOMETRY_ID` (a zeroed one
/// would claim geometry 0).
#[inline(always)]
fn empty_hit() -> sys::RTCHit {
    let mut hit = sys::RTCHit {
        geomID: sys::INVALID_GEOMETRY_ID,
        primID: sys::INVALID_GEOMETRY_ID,
        ..Default::default()
    };
    hit.instID.fill(sys::INVALID_GEOMETRY_ID);
    #[cfg(embree_instance_array)]
    hit.instPrimID.fill(sys::INVALID_GEOMETRY_ID);
    hit
}

/// `rtcIntersect1`/`rtcOccluded1`, whose arguments differ between Embree 3 and 4.
#[cfg(embree3)]
mod query {
    use super::sys;

    /// The context `rtcInitIntersectContext` (a static inline function bindgen drops)
    /// would produce: incoherent, no filter, empty instance stack (and, depending on the
    /// build, `instStackSize = 0`, `minWidthDistanceFactor = 0`: the zeroed default).
    #[inline(always)]
    fn context() -> sys::RTCIntersectContext {
        let mut ctx = sys::RTCIntersectContext {
            flags: sys::RTCIntersectContextFlags::RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT,
            filter: None,
            ..Default::default()
        };
        ctx.instID.fill(sys::INVALID_GEOMETRY_ID);
        ctx
    }

    #[inline(always)]
    pub(super) fn intersect(scene: sys::RTCScene, rayhit: &mut sys::RTCRayHit) {
        let mut ctx = context();
        // SAFETY: `scene` is live and committed; `ctx` is initialised as the header's
        // `rtcInitIntersectContext` does; `rayhit` is a valid, 16-byte aligned
        // `RTCRayHit` with mask, tnear <= tfar and invalid ids set.
        unsafe { sys::rtcIntersect1(scene, &mut ctx, rayhit) }
    }

    #[inline(always)]
    pub(super) fn occluded(scene: sys::RTCScene, ray: &mut sys::RTCRay) {
        let mut ctx = context();
        // SAFETY: as in `intersect`, for an `RTCRay`.
        unsafe { sys::rtcOccluded1(scene, &mut ctx, ray) }
    }

    /// `intersectN`/`occludedN(valid, scene, packet)`: `rtcIntersectN` or `rtcOccludedN`
    /// (same arguments in Embree 3) with a coherent context.
    macro_rules! packet {
        ($name:ident, $n:literal, $ty:ident, $f:ident) => {
            #[inline(always)]
            pub(super) fn $name(
                valid: &super::ValidMask<$n>,
                scene: sys::RTCScene,
                packet: &mut sys::$ty,
            ) {
                let mut ctx = context();
                ctx.flags = sys::RTCIntersectContextFlags::RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
                // SAFETY: `scene` is live and committed; `ctx` is initialised as in
                // `intersect`; `valid` has N entries and is aligned to 64 bytes (Embree
                // loads it as one vector); `packet` is an aligned packet (its type
                // carries the header's alignment) whose active rays have mask and
                // tnear <= tfar set (and, for a hit packet, invalid ids).
                unsafe { sys::$f(valid.0.as_ptr(), scene, &mut ctx, packet) }
            }
        };
    }
    packet!(intersect4, 4, RTCRayHit4, rtcIntersect4);
    packet!(intersect8, 8, RTCRayHit8, rtcIntersect8);
    packet!(intersect16, 16, RTCRayHit16, rtcIntersect16);
    packet!(occluded4, 4, RTCRay4, rtcOccluded4);
    packet!(occluded8, 8, RTCRay8, rtcOccluded8);
    packet!(occluded16, 16, RTCRay16, rtcOccluded16);
}

/// `rtcIntersect1`/`rtcOccluded1`, whose arguments differ between Embree 3 and 4.
#[cfg(embree4)]
// The argument structs have one more field (`minWidthDistanceFactor`) in Embree builds
// with min-width support; `..Default::default()` zeroes it there and is a no-op here.
#[allow(clippy::needless_update)]
mod query {
    use super::sys;

    /// What `rtcInitRayQueryContext` (static inline, dropped by bindgen) produces.
    #[inline(always)]
    fn context() -> sys::RTCRayQueryContext {
        let mut ctx = sys::RTCRayQueryContext::default();
        ctx.instID.fill(sys::INVALID_GEOMETRY_ID);
        #[cfg(embree_instance_array)]
        ctx.instPrimID.fill(sys::INVALID_GEOMETRY_ID);
        ctx
    }

    /// As `rtcInitIntersectArguments` with `flags`: all features, no filter or argument
    /// callbacks; plus our context.
    #[inline(always)]
    fn intersect_args(
        ctx: &mut sys::RTCRayQueryContext,
        flags: sys::RTCRayQueryFlags,
    ) -> sys::RTCIntersectArguments {
        sys::RTCIntersectArguments {
            flags,
            feature_mask: sys::RTCFeatureFlags::RTC_FEATURE_FLAG_ALL,
            context: ctx,
            filter: None,
            intersect: None,
            ..Default::default()
        }
    }

    #[inline(always)]
    pub(super) fn intersect(scene: sys::RTCScene, rayhit: &mut sys::RTCRayHit) {
        let mut ctx = context();
        let mut args = intersect_args(
            &mut ctx,
            sys::RTCRayQueryFlags::RTC_RAY_QUERY_FLAG_INCOHERENT,
        );
        // SAFETY: `scene` is live and committed; `args` and the context it points to are
        // initialised as the header's init functions do and outlive the call; `rayhit`
        // is a valid, 16-byte aligned `RTCRayHit` with mask, tnear <= tfar and invalid
        // ids set.
        unsafe { sys::rtcIntersect1(scene, rayhit, &mut args) }
    }

    #[inline(always)]
    pub(super) fn occluded(scene: sys::RTCScene, ray: &mut sys::RTCRay) {
        let mut ctx = context();
        let mut args = sys::RTCOccludedArguments {
            flags: sys::RTCRayQueryFlags::RTC_RAY_QUERY_FLAG_INCOHERENT,
            feature_mask: sys::RTCFeatureFlags::RTC_FEATURE_FLAG_ALL,
            context: &mut ctx,
            filter: None,
            occluded: None,
            ..Default::default()
        };
        // SAFETY: as in `intersect`, for an `RTCRay`.
        unsafe { sys::rtcOccluded1(scene, ray, &mut args) }
    }

    /// `intersectN(valid, scene, packet)`: `rtcIntersectN` flagged coherent.
    macro_rules! packet {
        ($name:ident, $n:literal, $ty:ident, $f:ident) => {
            #[inline(always)]
            pub(super) fn $name(
                valid: &super::ValidMask<$n>,
                scene: sys::RTCScene,
                rayhit: &mut sys::$ty,
            ) {
                let mut ctx = context();
                let mut args =
                    intersect_args(&mut ctx, sys::RTCRayQueryFlags::RTC_RAY_QUERY_FLAG_COHERENT);
                // SAFETY: as in `intersect`; `valid` has N entries and is aligned to 64
                // bytes (Embree loads it as one vector); `rayhit` is an aligned packet
                // whose active rays have mask, tnear <= tfar and invalid ids set.
                unsafe { sys::$f(valid.0.as_ptr(), scene, rayhit, &mut args) }
            }
        };
    }
    packet!(intersect4, 4, RTCRayHit4, rtcIntersect4);
    packet!(intersect8, 8, RTCRayHit8, rtcIntersect8);
    packet!(intersect16, 16, RTCRayHit16, rtcIntersect16);

    /// `occludedN(valid, scene, packet)`: `rtcOccludedN` flagged coherent.
    macro_rules! shadow_packet {
        ($name:ident, $n:literal, $ty:ident, $f:ident) => {
            #[inline(always)]
            pub(super) fn $name(
                valid: &super::ValidMask<$n>,
                scene: sys::RTCScene,
                ray: &mut sys::$ty,
            ) {
                let mut ctx = context();
                let mut args = sys::RTCOccludedArguments {
                    flags: sys::RTCRayQueryFlags::RTC_RAY_QUERY_FLAG_COHERENT,
                    feature_mask: sys::RTCFeatureFlags::RTC_FEATURE_FLAG_ALL,
                    context: &mut ctx,
                    filter: None,
                    occluded: None,
                    ..Default::default()
                };
                // SAFETY: as in `occluded`; `valid` has N entries and is aligned to 64
                // bytes (Embree loads it as one vector); `ray` is an aligned packet whose
                // active rays have mask and tnear <= tfar set.
                unsafe { sys::$f(valid.0.as_ptr(), scene, ray, &mut args) }
            }
        };
    }
    shadow_packet!(occluded4, 4, RTCRay4, rtcOccluded4);
    shadow_packet!(occluded8, 8, RTCRay8, rtcOccluded8);
    shadow_packet!(occluded16, 16, RTCRay16, rtcOccluded16);
}

/// One native triangle mesh holding all triangles, three vertices each, so that
/// `primID` is the index in `scene.triangles`.
fn attach_triangles(
    device: &Device,
    scene: &Level<'_>,
    tris: &[Triangle],
) -> Result<(), EmbreeError> {
    let count = tris.len();
    let too_many = || {
        EmbreeError::emray(
            "building the triangle mesh",
            format!("{count} triangles exceed Embree's 32-bit vertex indices"),
        )
    };
    let vertex_count = count
        .checked_mul(3)
        .filter(|&v| u32::try_from(v).is_ok())
        .ok_or_else(too_many)?;
    let geometry = Geometry::new(
        device,
        sys::RTCGeometryType::RTC_GEOMETRY_TYPE_TRIANGLE,
        "triangles",
    )?;

    // Embree allocates these buffers (and pads vertex buffers so the last vertex can be
    // read with a 16-byte load, as its SSE code does).
    // SAFETY: live geometry; stride 12 bytes (3 x f32 / 3 x u32) is 4-byte aligned.
    let vertices = unsafe {
        sys::rtcSetNewGeometryBuffer(
            geometry.0,
            sys::RTCBufferType::RTC_BUFFER_TYPE_VERTEX,
            0,
            sys::RTCFormat::RTC_FORMAT_FLOAT3,
            3 * size_of::<f32>(),
            vertex_count,
        )
    }
    .cast::<f32>();
    // SAFETY: as above.
    let indices = unsafe {
        sys::rtcSetNewGeometryBuffer(
            geometry.0,
            sys::RTCBufferType::RTC_BUFFER_TYPE_INDEX,
            0,
            sys::RTCFormat::RTC_FORMAT_UINT3,
            3 * size_of::<u32>(),
            count,
        )
    }
    .cast::<u32>();
    if vertices.is_null() || indices.is_null() {
        device.check("rtcSetNewGeometryBuffer(triangles)")?;
        return Err(EmbreeError::emray(
            "rtcSetNewGeometryBuffer(triangles)",
            "Embree returned no buffer",
        ));
    }
    // SAFETY: Embree returned buffers of `vertex_count` FLOAT3 and `count` UINT3 items,
    // suitably aligned for f32/u32, owned by the geometry (alive: we hold it), and not
    // aliased by anything else while these slices exist.
    let (vertices, indices) = unsafe {
        (
            std::slice::from_raw_parts_mut(vertices, vertex_count * 3),
            std::slice::from_raw_parts_mut(indices, vertex_count),
        )
    };
    for (tri, out) in tris.iter().zip(vertices.chunks_exact_mut(9)) {
        for (p, o) in tri.p.iter().zip(out.chunks_exact_mut(3)) {
            o.copy_from_slice(&p.to_array());
        }
    }
    for (i, idx) in (0u32..).zip(indices.iter_mut()) {
        *idx = i;
    }
    device.check("filling the triangle buffers")?;
    geometry.commit_and_attach(device, scene, Kind::Triangle as u32, "triangles")
}

/// One user geometry holding the primitives `ids` of the scene's list `items` of kind
/// `T::KIND` (all of them for `None`; no geometry when that is none), in runs of at
/// most `group` consecutive ids per Embree primitive (see `group`). Returns the boxed
/// user data Embree's callbacks read, which must outlive `scene`'s handle.
fn attach_user<'s, T: Analytic>(
    device: &Device,
    scene: &Level<'s>,
    items: &'s [T],
    ids: Option<Box<[u32]>>,
    group: usize,
) -> Result<Option<Box<UserPrims<'s, T>>>, EmbreeError> {
    let kind = T::KIND;
    let len = ids.as_ref().map_or(items.len(), |ids| ids.len());
    if len == 0 {
        return Ok(None);
    }
    if u32::try_from(len).is_err() {
        return Err(EmbreeError::emray(
            format!("building the {} geometry", kind.name()),
            format!("{len} primitives exceed Embree's 32-bit primitive ids"),
        ));
    }
    let data = Box::new(UserPrims::grouped(items, ids, group));
    if group > 1 {
        log::info!(
            "{} {} in {} groups of at most {group}",
            len,
            kind.name(),
            data.embree_count()
        );
    }
    let count = u32::try_from(data.embree_count()).unwrap_or(u32::MAX);
    let geometry = Geometry::new(
        device,
        sys::RTCGeometryType::RTC_GEOMETRY_TYPE_USER,
        kind.name(),
    )?;
    // SAFETY: live user geometry. The user pointer is the boxed `UserPrims<T>` that the
    // callbacks (instantiated for the same `T`) read; it is returned to the caller, who
    // stores it in the `CommittedScene`, where it is freed only after the scene is
    // released.
    unsafe {
        sys::rtcSetGeometryUserPrimitiveCount(geometry.0, count);
        sys::rtcSetGeometryUserData(geometry.0, data.as_user_ptr());
        sys::rtcSetGeometryBoundsFunction(
            geometry.0,
            Some(user::bounds::<T>),
            std::ptr::null_mut(),
        );
        sys::rtcSetGeometryIntersectFunction(geometry.0, Some(user::intersect::<T>));
        sys::rtcSetGeometryOccludedFunction(geometry.0, Some(user::occluded::<T>));
    }
    device.check(format!("setting up the {} geometry", kind.name()))?;
    geometry.commit_and_attach(device, scene, kind as u32, kind.name())?;
    Ok(Some(data))
}

/// An instance geometry placing `object` in `scene` under `xform`, as geometry `id`.
fn attach_instance(
    device: &Device,
    scene: &Level<'_>,
    object: &Level<'_>,
    xform: &Xform,
    id: u32,
) -> Result<(), EmbreeError> {
    let geometry = Geometry::new(
        device,
        sys::RTCGeometryType::RTC_GEOMETRY_TYPE_INSTANCE,
        "instance",
    )?;
    let m = xform.to_world;
    // Column-major 3×4: the three linear columns, then the translation.
    let cols: [f32; 12] = [
        m.matrix3.x_axis.x,
        m.matrix3.x_axis.y,
        m.matrix3.x_axis.z,
        m.matrix3.y_axis.x,
        m.matrix3.y_axis.y,
        m.matrix3.y_axis.z,
        m.matrix3.z_axis.x,
        m.matrix3.z_axis.y,
        m.matrix3.z_axis.z,
        m.translation.x,
        m.translation.y,
        m.translation.z,
    ];
    // SAFETY: live instance geometry and committed object scene of the same device;
    // `cols` holds the 12 floats `RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR` reads, and Embree
    // copies them before returning. The instance keeps its own reference to the object
    // scene.
    unsafe {
        sys::rtcSetGeometryInstancedScene(geometry.0, object.raw);
        sys::rtcSetGeometryTimeStepCount(geometry.0, 1);
        sys::rtcSetGeometryTransform(
            geometry.0,
            0,
            sys::RTCFormat::RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR,
            cols.as_ptr().cast(),
        );
    }
    device.check("setting up an instance")?;
    geometry.commit_and_attach(device, scene, id, "instance")
}
