//! What the `*_render` targets check once a scene has loaded.

/// The backends each input is rendered with: the pure-Rust BVH always, and Embree as
/// well when the fuzz crate is built with its `embree` feature (`cargo fuzz run
/// --features embree …`), so that a ray or a build Embree would refuse is caught too.
const BACKENDS: &[emray::accel::Backend] = &[
    emray::accel::Backend::Bvh,
    #[cfg(feature = "embree")]
    emray::accel::Backend::Embree,
];

/// Build each backend over `scene` and render a tiny image of it: no panic, no abort,
/// no hang (depth and area samples capped), and no NaN pixel.
pub fn render_has_no_nan(scene: &emray::Scene) {
    let mut settings = emray::render::RenderSettings::for_scene(scene);
    settings.width = 6;
    settings.height = 5;
    settings.max_depth = settings.max_depth.min(6);
    settings.spp = 1;
    settings.area_strata = settings.area_strata.min(2);
    for &backend in BACKENDS {
        if let Ok((film, _)) =
            emray::job::render_scene("fuzz", scene, backend, &settings, 0.0, None)
        {
            for (i, p) in film.pixels.iter().enumerate() {
                assert!(
                    !p.x.is_nan() && !p.y.is_nan() && !p.z.is_nan(),
                    "NaN at pixel {i} on {}: {p:?}",
                    backend.name()
                );
            }
        }
    }
}
