//! What the `*_render` targets check once a scene has loaded.

/// Build the BVH over `scene` and render a tiny image of it: no panic, no hang (depth
/// and area samples capped), and no NaN pixel.
pub fn render_has_no_nan(scene: &emray::Scene) {
    let mut settings = emray::RenderSettings::for_scene(scene);
    settings.width = 6;
    settings.height = 5;
    settings.max_depth = settings.max_depth.min(6);
    settings.spp = 1;
    settings.area_samples = settings.area_samples.min(2);
    if let Ok((film, _)) = emray::run::render_scene(
        "fuzz",
        scene,
        emray::accel::Backend::Bvh,
        &settings,
        0.0,
        None,
    ) {
        for (i, p) in film.pixels.iter().enumerate() {
            assert!(!p.x.is_nan() && !p.y.is_nan() && !p.z.is_nan(), "NaN at pixel {i}: {p:?}");
        }
    }
}
