//! `emray explain`'s text: the ray tree indented by depth, each ray with what it hit,
//! where that was defined, the light at the hit term by term, and what the ray brings
//! back (docs/explain.md shows an example).

use super::{Explanation, HitNode, LightNode, Position, Prim, RayNode};
use crate::render::record::{NotCast, Term};
use std::fmt::Write as _;

/// Indentation per ray-tree level.
const INDENT: &str = "    ";

/// The explanation as text.
pub fn format(e: &Explanation) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "pixel ({}, {}) of {}x{}: {}  (linear RGB, the film's value)",
        e.x,
        e.y,
        e.width,
        e.height,
        vec3(e.value)
    );
    let samples = if e.spd {
        "SPD mode: the mean of the pixel's four corner rays".to_string()
    } else if e.spp == 1 {
        "1 sample, at the pixel's centre".to_string()
    } else {
        format!("{} samples, averaged", e.spp)
    };
    let _ = writeln!(out, "{samples}; depth limit {}", e.max_depth);
    let sum: [f32; 3] = contributions(e);
    let _ = writeln!(
        out,
        "the rays' contributions sum to {} (rounding apart)",
        vec3(sum)
    );
    for (k, p) in e.positions.iter().enumerate() {
        position(&mut out, e, k, p);
    }
    out
}

/// The sum of every ray's own contribution to the pixel.
pub fn contributions(e: &Explanation) -> [f32; 3] {
    fn add(node: &RayNode, sum: &mut [f32; 3]) {
        if node.discarded {
            return;
        }
        for (s, c) in sum.iter_mut().zip(node.contribution) {
            *s += c;
        }
        if let Some(h) = &node.hit {
            for child in &h.children {
                add(child, sum);
            }
        }
    }
    let mut sum = [0.0; 3];
    for p in &e.positions {
        for s in &p.samples {
            add(s, &mut sum);
        }
    }
    sum
}

fn position(out: &mut String, e: &Explanation, k: usize, p: &Position) {
    let _ = writeln!(out);
    if e.spd {
        const CORNERS: [&str; 4] = ["top-left", "top-right", "bottom-left", "bottom-right"];
        let _ = writeln!(
            out,
            "{} corner, grid position ({}, {}): {}, 1/4 of the pixel",
            CORNERS.get(k).copied().unwrap_or("another"),
            p.grid[0],
            p.grid[1],
            vec3(p.value)
        );
    } else if p.samples.len() > 1 {
        let _ = writeln!(
            out,
            "{} samples of 1/{} each, mean {}",
            p.samples.len(),
            p.samples.len(),
            vec3(p.value)
        );
    }
    for (n, s) in p.samples.iter().enumerate() {
        if p.samples.len() > 1 {
            let _ = writeln!(out, "sample {}:", n + 1);
        }
        ray(out, s, 0);
    }
}

fn ray(out: &mut String, r: &RayNode, level: usize) {
    let pad = INDENT.repeat(level);
    let weight = if r.depth == 1 {
        String::new()
    } else {
        format!(
            ", weight {} (in the sample {})",
            vec3(r.local_weight),
            vec3(r.weight)
        )
    };
    let _ = writeln!(
        out,
        "{pad}{} ray, depth {}{weight}{}",
        r.kind.name(),
        r.depth,
        if r.discarded {
            " (cast as the SPD's reference casts it, its light not used)"
        } else {
            ""
        }
    );
    let _ = writeln!(
        out,
        "{pad}  from {} along {}",
        point(r.origin),
        point(r.direction)
    );
    for p in &r.passed {
        let _ = writeln!(
            out,
            "{pad}  goes through {} at {} ({} a lower-priority medium inside a higher one)",
            prim(&p.prim),
            point(p.point),
            if p.entering { "entering" } else { "leaving" }
        );
    }
    if let Some(bg) = r.background {
        let _ = writeln!(
            out,
            "{pad}  misses everything: background {}, adds {} to the pixel",
            vec3(bg),
            vec3(r.contribution)
        );
    }
    if let Some(h) = &r.hit {
        hit(out, h, &pad, r.contribution);
        for child in &h.children {
            ray(out, child, level + 1);
        }
        let _ = writeln!(out, "{pad}  radiance {}{}", vec3(r.radiance), sum_of(h));
    }
}

/// How a hit's radiance is made: `= local + w × refraction + ...`.
fn sum_of(h: &HitNode) -> String {
    let mut s = String::from(" = local");
    for c in h.children.iter().filter(|c| !c.discarded) {
        let _ = write!(s, " + {} × {}", vec3(c.local_weight), c.kind.name());
    }
    s
}

/// A hit: the surface, the light there term by term, and the branches.
fn hit(out: &mut String, h: &HitNode, pad: &str, contribution: [f32; 3]) {
    surface(out, h, pad);
    light_terms(out, h, pad);
    let _ = writeln!(
        out,
        "{pad}  local light {}, adds {} to the pixel",
        vec3(h.local),
        vec3(contribution)
    );
    branches(out, h, pad);
}

/// What was hit: the primitive, its side and normals, the material, the media.
fn surface(out: &mut String, h: &HitNode, pad: &str) {
    let _ = writeln!(
        out,
        "{pad}  hits {} at t = {}, point {}",
        prim(&h.prim),
        num(h.t),
        point(h.point)
    );
    let _ = writeln!(
        out,
        "{pad}  {}, shading normal {}, geometric normal {}",
        if h.entering {
            "front side"
        } else {
            "back side"
        },
        point(h.normal),
        point(h.geometric_normal)
    );
    let m = &h.material;
    let _ = writeln!(
        out,
        "{pad}  material {}{}: colour {}, Ka {}, Kd {}, Ks {}, Shine {}, Kr {}, T {}, ior {}{}",
        m.index,
        source(&m.source),
        vec3(m.color),
        num(m.ka),
        num(m.kd),
        num(m.ks),
        num(m.shine),
        num(m.kr),
        num(m.t),
        num(m.ior),
        if m.emission != [0.0; 3] {
            format!(", emission {}", vec3(m.emission))
        } else {
            String::new()
        }
    );
    let _ = writeln!(out, "{pad}  in {}", media(&h.media));
}

/// The local light's terms, area lights and point lights.
fn light_terms(out: &mut String, h: &HitNode, pad: &str) {
    for t in &h.terms {
        let name = match t.term {
            Term::Ambient => "ambient",
            Term::Emission => "emission",
            Term::Area => "area lights",
            Term::Radiosity => "radiosity (replaces ambient, emission and area lights)",
        };
        let _ = writeln!(out, "{pad}  {name}: {}", vec3(t.value));
    }
    for a in &h.area_lights {
        let _ = writeln!(
            out,
            "{pad}    area light {}: {} of {} shadow rays reach it, direct term {}",
            a.light,
            a.visible,
            a.rays,
            vec3(a.value)
        );
    }
    for l in &h.lights {
        light(out, l, pad);
    }
}

/// Snell's law at a transmissive surface, and the rays not cast.
fn branches(out: &mut String, h: &HitNode, pad: &str) {
    if let Some(b) = &h.boundary {
        let _ = writeln!(
            out,
            "{pad}  refraction from index {} into {} ({}){}",
            num(b.n1),
            num(b.n2),
            media(&b.media_beyond),
            if b.total_internal_reflection {
                ": total internal reflection, T goes to the reflection"
            } else {
                ""
            }
        );
    }
    for n in &h.not_cast {
        let why = match n.why {
            NotCast::Bailout => "its weight is below --bailout",
            NotCast::NoReflectance => "Kr = 0",
        };
        let _ = writeln!(
            out,
            "{pad}  no {} ray: {why} (weight {})",
            n.kind.name(),
            vec3(n.weight)
        );
    }
}

fn light(out: &mut String, l: &LightNode, pad: &str) {
    let _ = write!(
        out,
        "{pad}  light {}{}: {}",
        l.light,
        source(&l.source),
        l.status
    );
    match l.status {
        "lit" => {
            let _ = writeln!(
                out,
                ", intensity {} (attenuation {})",
                vec3(l.intensity),
                num(l.attenuation)
            );
            let _ = writeln!(
                out,
                "{pad}    diffuse {} + specular {}, adds {}",
                vec3(l.diffuse),
                num(l.specular),
                vec3(l.value)
            );
        }
        "behind" => {
            let _ = writeln!(
                out,
                " (behind the surface or sending nothing: no shadow ray)"
            );
        }
        _ => {
            let _ = writeln!(out);
        }
    }
    if let Some(s) = &l.shadow_ray {
        let _ = writeln!(
            out,
            "{pad}    shadow ray from {} along {} up to t = {}: {}",
            point(s.origin),
            point(s.direction),
            num(s.tmax),
            if s.occluded { "blocked" } else { "clear" }
        );
    }
}

fn prim(p: &Prim) -> String {
    let mut s = format!("{} {}{}", p.kind, p.index, source(&p.source));
    if let Some(i) = p.instance {
        let _ = write!(s, " of instance {i}{}", source(&p.instance_source));
    }
    s
}

fn media(m: &[super::Medium]) -> String {
    if m.is_empty() {
        return "air (index 1)".into();
    }
    let list: Vec<String> = m
        .iter()
        .map(|x| format!("material {} (index {})", x.material, num(x.ior)))
        .collect();
    format!("media {}", list.join(" > "))
}

fn source(s: &Option<String>) -> String {
    s.as_ref().map(|s| format!(" ({s})")).unwrap_or_default()
}

/// A number with at most six significant digits.
fn num(x: impl Into<f64>) -> String {
    let x: f64 = x.into();
    if x == 0.0 {
        return "0".into();
    }
    if !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if (1e-4..1e6).contains(&a) {
        let digits = (5 - a.log10().floor() as i32).clamp(0, 9) as usize;
        let s = format!("{x:.digits$}");
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        };
        if s == "-0" { "0".into() } else { s }
    } else {
        format!("{x:.5e}")
    }
}

fn vec3<T: Into<f64> + Copy>(v: [T; 3]) -> String {
    format!("{} {} {}", num(v[0]), num(v[1]), num(v[2]))
}

fn point<T: Into<f64> + Copy>(v: [T; 3]) -> String {
    format!("({})", vec3(v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_have_six_significant_digits() {
        assert_eq!(num(0.318_442_05), "0.318442");
        assert_eq!(num(1.0), "1");
        assert_eq!(num(1234.5678), "1234.57");
        assert_eq!(num(-0.5), "-0.5");
        assert_eq!(num(0.0), "0");
        assert_eq!(num(-0.0), "0");
        assert_eq!(num(1e-7), "1.00000e-7");
        assert_eq!(num(f32::INFINITY), "inf");
    }
}
