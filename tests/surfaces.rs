//! Surfaces in bulk ([`Scene::surfaces`], what the wavefront shades from) against one
//! hit at a time ([`Scene::surface_of`]): the same values bit for bit, on every
//! primitive kind, in instances, with and without texture parameters, for runs of
//! one kind and for runs that mix kinds, on both backends and with the triangle hits
//! re-tested or taken as they are.

use emray::Hit;
use emray::accel::Accel;
use emray::accel::bvh::Bvh;
use emray::geometry::Kind;
use emray::load::load_path;
use emray::math::Ray;
use emray::render::RayGen;
use emray::scene::{Maps, NO_INSTANCE, Scene, Surfaces, Texture};
use glam::Vec3;
use std::collections::BTreeSet;
use std::path::Path;

/// `scenes/primitives.toml` (every kind, instances), every other material given a
/// checker texture so that some hits carry texture parameters.
fn scene() -> Scene {
    let mut s = load_path(Path::new("scenes/primitives.toml")).expect("the scene loads");
    s.textures.push(Texture::Checker {
        a: Vec3::ONE,
        b: Vec3::splat(0.5),
        scale: 4.0,
    });
    let checker = s.textures.len() as u32 - 1;
    for m in s.materials.iter_mut().step_by(2) {
        m.maps = Maps {
            color: checker,
            ..Maps::NONE
        };
    }
    s
}

/// The camera's rays through a grid of pixel centres, and their nearest hits.
fn cast(s: &Scene, accel: &impl Accel) -> (Vec<Ray>, Vec<Option<Hit>>) {
    let (w, h) = (96, 72);
    let camera = RayGen::new(&s.camera, w, h);
    let rays: Vec<Ray> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| camera.ray(x as f32 + 0.5, y as f32 + 0.5))
        .collect();
    let hits = rays.iter().map(|r| accel.intersect(r)).collect();
    (rays, hits)
}

/// Surface `k` of `bulk` is `surface_of`'s for hit `i`, bit for bit.
fn assert_same(
    s: &Scene,
    bulk: &Surfaces,
    k: usize,
    i: usize,
    cast: &(Vec<Ray>, Vec<Option<Hit>>),
    exact: bool,
) {
    let hit = cast.1[i].as_ref().unwrap();
    let want = s.surface_of(hit, &cast.0[i], exact);
    let got = bulk.get(k);
    // Compared as bits: equal floats, and the same NaNs if there were any.
    assert_eq!(format!("{got:?}"), format!("{want:?}"), "hit {i}: {hit:?}");
}

/// Every hit through `Scene::surfaces`, in runs of one kind and in one mixed run;
/// what was covered (kinds, instance hits, textured hits).
fn check(s: &Scene, accel: &impl Accel, exact: bool) -> (BTreeSet<u32>, usize, usize) {
    let cast = cast(s, accel);
    let hit_ids: Vec<u32> = (0..cast.1.len() as u32)
        .filter(|&i| cast.1[i as usize].is_some())
        .collect();
    let mut bulk = Surfaces::default();
    let mut kinds = BTreeSet::new();
    let mut instanced = 0;
    for kind in Kind::ALL {
        let run: Vec<u32> = hit_ids
            .iter()
            .copied()
            .filter(|&i| cast.1[i as usize].unwrap().geom_id == kind as u32)
            .collect();
        bulk.clear(run.len());
        s.surfaces(&run, &cast.1, &cast.0, exact, &mut bulk);
        assert_eq!(bulk.len(), run.len());
        for (k, &i) in run.iter().enumerate() {
            assert_same(s, &bulk, k, i as usize, &cast, exact);
            kinds.insert(kind as u32);
            instanced += usize::from(cast.1[i as usize].unwrap().inst_id != NO_INSTANCE);
        }
    }
    // One run of every kind in cast order: each hit of a kind other than the first
    // one's goes through the general path and still comes out the same.
    bulk.clear(0);
    s.surfaces(&hit_ids, &cast.1, &cast.0, exact, &mut bulk);
    assert_eq!(bulk.len(), hit_ids.len());
    let mut textured = 0;
    for (k, &i) in hit_ids.iter().enumerate() {
        assert_same(s, &bulk, k, i as usize, &cast, exact);
        textured += usize::from(bulk.get(k).param.is_some());
    }
    (kinds, instanced, textured)
}

fn check_accel(s: &Scene, accel: &impl Accel) {
    for exact in [false, true] {
        let (kinds, instanced, textured) = check(s, accel, exact);
        assert!(kinds.len() >= 8, "kinds hit: {kinds:?}");
        assert!(kinds.contains(&(Kind::Triangle as u32)), "{kinds:?}");
        assert!(instanced > 20, "instance hits: {instanced}");
        assert!(textured > 100, "textured hits: {textured}");
    }
}

#[test]
fn bulk_surfaces_are_one_by_one_surfaces_on_the_bvh() {
    let s = scene();
    check_accel(&s, &Bvh::build(&s));
}

#[cfg(feature = "embree")]
#[test]
fn bulk_surfaces_are_one_by_one_surfaces_on_embree() {
    let s = scene();
    let accel = emray::accel::embree::EmbreeAccel::build(&s).expect("Embree builds the scene");
    check_accel(&s, &accel);
}

#[test]
fn an_empty_run_adds_nothing() {
    let s = scene();
    let mut bulk = Surfaces::default();
    s.surfaces(&[], &[], &[], false, &mut bulk);
    assert!(bulk.is_empty());
}
