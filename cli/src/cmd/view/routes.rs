//! What each path answers, once [`Guard`] has let the request in:
//!
//! - `/`, `/view.js`, `/view.css`: the page (`/?token=…` also sets the cookie);
//! - `/status?gen=G&since=N`: the render under way and the last image, as JSON, with
//!   the tiles of render `G` from the `N`th on;
//! - `/render?backend=&res=&spp=&max-depth=&aa=&heatmaps=0|1&aovs=0|1&compare=0|1`: render
//!   with these options now (400 and the message `emray render` gives for options it
//!   refuses); `/compare?…` is `/render?…&compare=1`, Embree's render and the BVH's
//!   with their difference;
//! - `/image.png?layer=colour|rays|time|depth|bvh|difference|aov-NAME`: a layer of
//!   the last image (`aov-NAME`: output variable `NAME`, rendered with `aovs=1`);
//! - `/explain?x=&y=`: pixel `(x, y)`'s tree, as `emray explain --json` prints it;
//! - `/rays?x=&y=`: its rays projected into the image, and the same tree.

use super::assets;
use super::auth::{Access, Guard};
use super::http::{Request, Response};
use super::session::Session;
use serde_json::json;
use std::sync::Arc;

/// The server's state.
pub struct App {
    /// Who may come in.
    pub guard: Guard,
    /// The render.
    pub session: Arc<Session>,
}

/// Answer `req`.
pub fn handle(app: &App, req: &Request) -> Response {
    let access = match app.guard.check(req) {
        Ok(a) => a,
        Err(refusal) => return Response::text(403, refusal.to_string()),
    };
    let s = &app.session;
    match req.path.as_str() {
        "/" => {
            let mut r = Response::new(200, "text/html; charset=utf-8", assets::INDEX_HTML);
            if access == Access::Query {
                r.headers.push(("Set-Cookie", app.guard.set_cookie()));
            }
            r
        }
        "/view.js" => Response::new(200, "text/javascript; charset=utf-8", assets::VIEW_JS),
        "/view.css" => Response::new(200, "text/css; charset=utf-8", assets::VIEW_CSS),
        "/status" => {
            let generation = number(req, "gen").unwrap_or(0);
            let since = number(req, "since").unwrap_or(0) as usize;
            Response::json(200, &s.status(generation, since))
        }
        "/render" | "/compare" => {
            let heatmaps = req.param("heatmaps").is_some_and(|v| v == "1");
            let aovs = req.param("aovs").is_some_and(|v| v == "1");
            let compare = req.path == "/compare" || req.param("compare").is_some_and(|v| v == "1");
            match s.parse(&req.query, heatmaps, aovs, compare) {
                Ok(request) => Response::json(200, &json!({"generation": s.submit(request)})),
                Err(e) => Response::json(400, &json!({"error": e})),
            }
        }
        "/image.png" => match s.layer(req.param("layer").unwrap_or("colour")) {
            Some(png) => Response::new(200, "image/png", png),
            None => Response::text(404, "no such image yet\n"),
        },
        "/explain" | "/rays" => {
            let (Some(x), Some(y)) = (number(req, "x"), number(req, "y")) else {
                return Response::json(400, &json!({"error": "explain needs x and y"}));
            };
            let (Ok(x), Ok(y)) = (u32::try_from(x), u32::try_from(y)) else {
                return Response::json(400, &json!({"error": "x and y are pixels"}));
            };
            let answer = if req.path == "/rays" {
                s.rays(x, y)
            } else {
                s.explain(x, y)
            };
            match answer {
                Ok(text) => Response::new(200, "application/json", text),
                Err((usage, e)) => {
                    Response::json(if usage { 400 } else { 409 }, &json!({"error": e}))
                }
            }
        }
        _ => Response::text(404, "not found\n"),
    }
}

/// Query parameter `name` as a number.
fn number(req: &Request, name: &str) -> Option<u64> {
    req.param(name)?.parse().ok()
}
