//! `emray view` driven over HTTP as a browser would: the URL line, the token and Host
//! checks, progress, the final image against `emray render`'s, a pixel's tree against
//! `emray explain --json`'s, and the scene file broken and fixed.

mod common;

use common::{emray, repo};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A running `emray view`, killed when dropped (a failed assertion included).
struct Server {
    child: Child,
    port: u16,
    token: String,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Start `emray view` in `dir` with `args`, and read its URL line.
fn start(dir: &Path, args: &[&str]) -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_emray"))
        .current_dir(dir)
        .arg("view")
        .args(["--listen", "127.0.0.1:0", "-q"])
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("start emray view");
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let url = line.trim().strip_prefix("url ").expect(&line).to_string();
    let rest = url.strip_prefix("http://127.0.0.1:").expect(&url);
    let (port, token) = rest.split_once("/?token=").expect(&url);
    assert_eq!(token.len(), 32, "{url}");
    Server {
        port: port.parse().unwrap(),
        token: token.to_string(),
        child,
    }
}

/// A response's status and body.
struct Reply {
    status: u16,
    body: Vec<u8>,
}

impl Reply {
    fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }
    fn json(&self) -> serde_json::Value {
        serde_json::from_slice(&self.body).unwrap_or_else(|e| panic!("{e}: {}", self.text()))
    }
}

impl Server {
    /// `GET path` with `host` as the Host header.
    fn get_as(&self, host: &str, path: &str) -> Reply {
        let mut s = TcpStream::connect(("127.0.0.1", self.port)).unwrap();
        write!(s, "GET {path} HTTP/1.1\r\nHost: {host}\r\n\r\n").unwrap();
        let mut raw = Vec::new();
        s.read_to_end(&mut raw).unwrap();
        let split = raw.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
        let head = String::from_utf8_lossy(&raw[..split]).into_owned();
        let status = head.split(' ').nth(1).unwrap().parse().unwrap();
        Reply {
            status,
            body: raw[split + 4..].to_vec(),
        }
    }

    /// `GET path` with the token.
    fn get(&self, path: &str) -> Reply {
        let sep = if path.contains('?') { '&' } else { '?' };
        let path = format!("{path}{sep}token={}", self.token);
        self.get_as(&format!("127.0.0.1:{}", self.port), &path)
    }

    /// Poll the status until `done` says so (at most a minute).
    fn wait(&self, done: impl Fn(&serde_json::Value) -> bool) -> serde_json::Value {
        let start = Instant::now();
        loop {
            let st = self.get("/status").json();
            if done(&st) {
                return st;
            }
            assert!(start.elapsed() < Duration::from_secs(60), "{st}");
            std::thread::sleep(Duration::from_millis(100));
        }
    }
}

/// Whether the status shows image `generation` or a later one, finished.
fn finished(st: &serde_json::Value, generation: u64) -> bool {
    st["image"]["generation"]
        .as_u64()
        .is_some_and(|g| g >= generation)
        && st["render"]["phase"] == "done"
}

const OPTIONS: [&str; 4] = ["--res", "80x60", "--backend", "bvh"];

#[test]
fn the_image_and_the_explanation_are_the_commands_own() {
    let dir = tempfile::tempdir().unwrap();
    let scene = repo().join("scenes/default.nff");
    let scene = scene.to_str().unwrap();
    let server = start(dir.path(), &[&[scene][..], &OPTIONS].concat());
    let st = server.wait(|st| finished(st, 1));
    let r = &st["render"];
    assert_eq!(
        (r["width"].as_u64(), r["height"].as_u64()),
        (Some(80), Some(60))
    );
    assert!(r["total"].as_u64().unwrap() > 1, "{r}");
    assert_eq!(r["done"], r["total"]);
    assert_eq!(r["loaded"], 100, "the load told its end: {r}");
    for phase in ["load", "build", "render"] {
        assert!(r["timings"][phase].as_f64().unwrap() >= 0.0, "{r}");
    }
    // Every tile was told, and the final PNG is `emray render`'s, byte for byte.
    let tiles = server.get("/status?gen=1&since=0").json();
    let told = tiles["render"]["tiles"].as_array().unwrap().len() as u64;
    assert_eq!(Some(told), r["total"].as_u64());
    let png = server.get("/image.png");
    assert_eq!(png.status, 200);
    let out = dir.path().join("render.png");
    let o = emray(
        dir.path(),
        &[
            &["render", scene, "-q", "-o", out.to_str().unwrap()][..],
            &OPTIONS,
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", common::stderr(&o));
    assert!(png.body == std::fs::read(&out).unwrap(), "the PNGs differ");

    let e = server.get("/explain?x=40&y=30");
    assert_eq!(e.status, 200, "{}", e.text());
    let o = emray(
        dir.path(),
        &[&["explain", scene, "40", "30", "--json"][..], &OPTIONS].concat(),
    );
    assert_eq!(e.text(), String::from_utf8_lossy(&o.stdout));
    assert_eq!(
        server.get("/explain?x=80&y=0").status,
        400,
        "outside the image"
    );

    // New options: a render of the new size, and refused ones with render's message.
    let g = server.get("/render?res=40x30&spp=2").json()["generation"]
        .as_u64()
        .unwrap();
    let st = server.wait(|st| finished(st, g));
    assert_eq!(st["image"]["width"], 40);
    let bad = server.get("/render?res=100000x100000");
    assert_eq!(bad.status, 400);
    assert!(bad.text().contains("too large"), "{}", bad.text());
    let bad = server.get("/render?spp=0");
    assert!(
        bad.text().contains("spp must be 1 to 65536"),
        "{}",
        bad.text()
    );
    // Heat maps are layers of their own.
    let g = server.get("/render?heatmaps=1").json()["generation"]
        .as_u64()
        .unwrap();
    let st = server.wait(|st| finished(st, g));
    assert_eq!(
        st["image"]["layers"],
        serde_json::json!(["colour", "rays", "time", "depth"])
    );
    let rays = server.get("/image.png?layer=rays");
    assert_eq!((rays.status, &rays.body[1..4]), (200, &b"PNG"[..]));
}

#[test]
fn requests_without_the_token_or_from_another_host_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let server = start(dir.path(), &["spd:balls?size=1", "--res", "16x16"]);
    let own = format!("127.0.0.1:{}", server.port);
    assert_eq!(server.get_as(&own, "/").status, 403);
    assert_eq!(server.get_as(&own, "/status?token=0000").status, 403);
    let evil = format!("evil.example:{}", server.port);
    let with_token = format!("/?token={}", server.token);
    assert_eq!(server.get_as(&evil, &with_token).status, 403);
    assert_eq!(server.get_as(&own, &with_token).status, 200);
    let localhost = format!("localhost:{}", server.port);
    assert_eq!(server.get_as(&localhost, &with_token).status, 200);
    assert_eq!(server.get("/../Cargo.toml").status, 404);
}

#[test]
fn a_broken_scene_is_reported_and_the_fixed_one_rendered() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.nff");
    let good = std::fs::read_to_string(repo().join("scenes/default.nff")).unwrap();
    std::fs::write(&scene, &good).unwrap();
    let server = start(dir.path(), &["s.nff", "--res", "32x24", "--backend", "bvh"]);
    server.wait(|st| finished(st, 1));
    let first = server.get("/image.png").body;
    // A line that does not parse, on line 3.
    let lines: Vec<&str> = good.lines().collect();
    let broken = format!(
        "{}\n{}\ns 1 2\n{}\n",
        lines[0],
        lines[1],
        lines[2..].join("\n")
    );
    std::fs::write(&scene, broken).unwrap();
    let st = server.wait(|st| st["render"]["phase"] == "failed");
    let error = st["render"]["error"].as_str().unwrap();
    assert!(error.contains("s.nff:3:"), "{error}");
    let col = error.split("s.nff:3:").nth(1).unwrap();
    assert!(
        col.starts_with(|c: char| c.is_ascii_digit()),
        "file:line:col: {error}"
    );
    // The last good image stays.
    assert_eq!(server.get("/image.png").body, first);
    std::fs::write(&scene, &good).unwrap();
    let g = st["wanted"].as_u64().unwrap() + 1;
    let st = server.wait(|st| finished(st, g));
    assert!(st["render"]["error"].is_null(), "{st}");
    assert_eq!(server.get("/image.png").body, first);
}

/// A mirror sphere over a floor, with a red sphere beside it: spheres and polygons,
/// which both backends render alike.
const MIRROR: &str = "v
from 0 -8 4
at 0 0 1
up 0 0 1
angle 40
hither 0.01
resolution 80 60
b 0.2 0.3 0.5
l 4 -4 8
f 0.8 0.8 0.8 0.1 0.9 30 0 1
s 0 0 1 1
f 0.9 0.2 0.2 0.8 0.1 10 0 1
s 2 -1 0.6 0.6
f 0.6 0.6 0.5 0.9 0 1 0 1
p 4
-6 -6 0
6 -6 0
6 6 0
-6 6 0
";

#[test]
fn a_pixels_rays_are_projected_where_they_show() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("mirror.nff"), MIRROR).unwrap();
    let server = start(dir.path(), &["mirror.nff", "--backend", "bvh"]);
    server.wait(|st| finished(st, 1));
    let (x, y) = (40.0, 34.0);
    let r = server.get("/rays?x=40&y=34");
    assert_eq!(r.status, 200, "{}", r.text());
    let r = r.json();
    // The tree is the one /explain gives.
    assert_eq!(r["tree"], server.get("/explain?x=40&y=34").json());
    let segments = r["segments"].as_array().unwrap();
    let point = |v: &serde_json::Value| (v[0].as_f64().unwrap(), v[1].as_f64().unwrap());
    let near =
        |(a, b): (f64, f64), (c, d): (f64, f64)| (a - c).abs() <= 1.0 && (b - d).abs() <= 1.0;
    let centre = (x + 0.5, y + 0.5);
    // The eye ray ends at its pixel, and shows there.
    let eye = &segments[0];
    assert_eq!(
        (
            eye["kind"].as_str(),
            eye["path"].as_str(),
            eye["ends"].as_str()
        ),
        (Some("eye"), Some("0.0"), Some("hit"))
    );
    assert!(near(point(&eye["end"]), centre), "{eye}");
    assert!(near(point(&eye["line"][1]), centre), "{eye}");
    // The mirror's reflection starts there and hits the floor inside the image.
    let reflection = segments
        .iter()
        .find(|s| s["kind"] == "reflection" && s["path"] == "0.0.0")
        .unwrap_or_else(|| panic!("no reflection: {segments:?}"));
    assert_eq!(reflection["ends"], "hit", "{reflection}");
    assert!(near(point(&reflection["line"][0]), centre), "{reflection}");
    let (ex, ey) = point(&reflection["end"]);
    assert!(
        (0.0..80.0).contains(&ex) && (0.0..60.0).contains(&ey),
        "{reflection}"
    );
    assert!(
        !near((ex, ey), centre),
        "the reflection goes somewhere: {reflection}"
    );
    // Shadow rays are there too, each with how it ended.
    assert!(
        segments
            .iter()
            .any(|s| s["kind"] == "shadow" && (s["ends"] == "light" || s["ends"] == "blocked")),
        "{segments:?}"
    );
    assert_eq!(
        server.get("/rays?x=80&y=0").status,
        400,
        "outside the image"
    );
}

#[test]
fn the_backends_are_compared_or_the_build_says_why_not() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("mirror.nff"), MIRROR).unwrap();
    let server = start(dir.path(), &["mirror.nff", "--res", "64x48"]);
    server.wait(|st| finished(st, 1));
    let asked = server.get("/compare");
    if !cfg!(feature = "embree") {
        assert_eq!(asked.status, 400);
        assert!(asked.text().contains("without Embree"), "{}", asked.text());
        assert_eq!(
            server.get("/status").json()["backends"],
            serde_json::json!(["bvh"])
        );
        return;
    }
    assert_eq!(asked.status, 200, "{}", asked.text());
    let g = asked.json()["generation"].as_u64().unwrap();
    let st = server.wait(|st| finished(st, g));
    let image = &st["image"];
    assert_eq!(
        image["layers"],
        serde_json::json!(["colour", "bvh", "difference"])
    );
    let c = &image["compare"];
    assert_eq!(
        (c["width"].as_u64(), c["height"].as_u64()),
        (Some(64), Some(48)),
        "{c}"
    );
    assert_eq!(
        (c["differing"].as_u64(), c["max"].as_u64()),
        (Some(0), Some(0)),
        "{c}"
    );
    let png = server.get("/image.png?layer=difference");
    assert_eq!(png.status, 200);
    let diff = image::load_from_memory(&png.body).unwrap().to_rgb8();
    assert_eq!(diff.dimensions(), (64, 48));
    assert!(
        diff.pixels().all(|p| p.0 == [0, 0, 0]),
        "no difference shown"
    );
    // The BVH's image is its own render's: `emray render --backend bvh`'s.
    let out = dir.path().join("bvh.png");
    let o = emray(
        dir.path(),
        &[
            "render",
            "mirror.nff",
            "-q",
            "--res",
            "64x48",
            "--backend",
            "bvh",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", common::stderr(&o));
    assert!(server.get("/image.png?layer=bvh").body == std::fs::read(&out).unwrap());
    // Unticked, a render makes one image again.
    let g = server.get("/render?compare=0").json()["generation"]
        .as_u64()
        .unwrap();
    let st = server.wait(|st| finished(st, g));
    assert_eq!(st["image"]["layers"], serde_json::json!(["colour"]));
    assert!(st["image"]["compare"].is_null());
}

/// A unit sphere at the origin seen from `z = 5`, looking down -z, on black.
const SPHERE: &str = "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 64 64\n\
                      b 0 0 0\nl 5 5 5\nf 0.8 0.3 0.2 1 0 0 0 1\ns 0 0 0 1\n";

#[test]
fn each_output_variable_is_a_layer() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("sphere.nff"), SPHERE).unwrap();
    let server = start(
        dir.path(),
        &["sphere.nff", "--res", "64x48", "--backend", "bvh"],
    );
    server.wait(|st| finished(st, 1));
    assert_eq!(server.get("/image.png?layer=aov-normal").status, 404);
    let g = server.get("/render?aovs=1").json()["generation"]
        .as_u64()
        .unwrap();
    let st = server.wait(|st| finished(st, g));
    assert_eq!(st["request"]["aovs"], true);
    let layers = st["image"]["layers"].as_array().unwrap();
    for name in [
        "colour",
        "aov-depth",
        "aov-normal",
        "aov-albedo",
        "aov-position",
        "aov-id",
        "aov-rays",
        "aov-time",
    ] {
        assert!(layers.iter().any(|l| l == name), "{name}: {layers:?}");
    }
    let layer = |name: &str| {
        let png = server.get(&format!("/image.png?layer={name}"));
        assert_eq!(png.status, 200, "{name}");
        let img = image::load_from_memory(&png.body).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (64, 48), "{name}");
        img
    };
    // The sphere's centre faces the eye, down the view's -z: its normal is +z, blue.
    let normal = layer("aov-normal");
    let c = normal.get_pixel(32, 24).0;
    assert!(c[2] >= 245, "{c:?}");
    assert!(
        c[0].abs_diff(128) <= 12 && c[1].abs_diff(128) <= 12,
        "{c:?}"
    );
    assert_eq!(normal.get_pixel(1, 1).0, [0, 0, 0], "the background");
    // Depth: nearer is lighter; the background is black; the range is told.
    let depth = layer("aov-depth");
    let near = depth.get_pixel(32, 24).0[0];
    let far = depth.get_pixel(32, 24 - 12).0[0];
    assert!(near > far && far > 0, "near {near}, far {far}");
    assert_eq!(depth.get_pixel(1, 1).0, [0, 0, 0], "the background");
    let range = &st["image"]["aov"]["depth"];
    let (min, max) = (
        range["min"].as_f64().unwrap(),
        range["max"].as_f64().unwrap(),
    );
    assert!(
        (3.9..4.1).contains(&min) && min < max && max < 5.0,
        "{range}"
    );
    // Gathering them leaves the colour `emray render`'s, byte for byte.
    let out = dir.path().join("render.png");
    let args = ["render", "sphere.nff", "-q", "-o", out.to_str().unwrap()];
    let o = emray(
        dir.path(),
        &[&args[..], &OPTIONS[2..], &["--res", "64x48"]].concat(),
    );
    assert!(o.status.success(), "{}", common::stderr(&o));
    assert!(server.get("/image.png").body == std::fs::read(&out).unwrap());
    // The albedo is the material's colour, sRGB encoded; the id one colour on the sphere.
    assert!(layer("aov-albedo").get_pixel(32, 24).0[0] > 200);
    let id = layer("aov-id");
    assert_ne!(id.get_pixel(32, 24).0, [0, 0, 0]);
    assert_eq!(id.get_pixel(32, 24), id.get_pixel(30, 20));
    assert_eq!(id.get_pixel(1, 1).0, [0, 0, 0]);
    // Refused as `emray render --aov` refuses it.
    let bad = server.get("/render?aovs=1&aa=adaptive");
    assert_eq!(bad.status, 400);
    assert!(bad.text().contains("--aa adaptive"), "{}", bad.text());
}
