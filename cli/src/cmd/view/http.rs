//! The little HTTP/1.1 the viewer needs, over `std::net`: one request per connection
//! (`Connection: close`), `GET` and `HEAD` only, a head of at most 16 KiB read within
//! a few seconds, no body. Each connection is served on a thread of its own, at most
//! [`MAX_CONNECTIONS`] at once.

use std::io::{self, BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

/// The longest request head read.
const MAX_HEAD: u64 = 16 * 1024;
/// Connections served at once; more are answered 503.
pub const MAX_CONNECTIONS: usize = 64;
/// How long a client has to send its request.
const READ_TIMEOUT: Duration = Duration::from_secs(5);

/// A request's line and headers.
#[derive(Debug, Default, PartialEq)]
pub struct Request {
    /// `GET` or `HEAD` (anything else is refused before it gets here).
    pub method: String,
    /// The path, without its query.
    pub path: String,
    /// The query's parameters, percent-decoded, in order.
    pub query: Vec<(String, String)>,
    /// The headers, names in lower case.
    pub headers: Vec<(String, String)>,
}

impl Request {
    /// The first header `name` (lower case).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// The first query parameter `name`.
    pub fn param(&self, name: &str) -> Option<&str> {
        self.query
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// The cookie `name` of the `Cookie` headers.
    pub fn cookie(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .filter(|(k, _)| k == "cookie")
            .flat_map(|(_, v)| v.split(';'))
            .filter_map(|c| c.trim().split_once('='))
            .find(|(k, _)| *k == name)
            .map(|(_, v)| v)
    }
}

/// A response: status, type, body and extra headers.
#[derive(Debug)]
pub struct Response {
    /// Status code.
    pub status: u16,
    /// `Content-Type`.
    pub content_type: &'static str,
    /// The body.
    pub body: Vec<u8>,
    /// More headers.
    pub headers: Vec<(&'static str, String)>,
}

impl Response {
    /// A `status` response of type `content_type`.
    pub fn new(status: u16, content_type: &'static str, body: impl Into<Vec<u8>>) -> Self {
        Response {
            status,
            content_type,
            body: body.into(),
            headers: Vec::new(),
        }
    }

    /// A plain-text `status` response.
    pub fn text(status: u16, body: impl Into<String>) -> Self {
        Response::new(status, "text/plain; charset=utf-8", body.into())
    }

    /// A JSON response.
    pub fn json(status: u16, value: &serde_json::Value) -> Self {
        Response::new(status, "application/json", value.to_string())
    }
}

/// Why a request could not be read.
#[derive(Debug, PartialEq)]
pub enum BadRequest {
    /// Not HTTP, or too long, or cut short: answered 400.
    Malformed(&'static str),
    /// A method other than `GET` and `HEAD`: answered 405.
    Method,
}

/// Read a request's head from `r`.
pub fn read_request(r: impl Read) -> Result<Request, BadRequest> {
    let mut r = BufReader::new(r.take(MAX_HEAD));
    let mut line = String::new();
    let read = |r: &mut BufReader<_>, line: &mut String| -> Result<(), BadRequest> {
        line.clear();
        match r.read_line(line) {
            Ok(0) | Err(_) => Err(BadRequest::Malformed("incomplete request")),
            Ok(_) if !line.ends_with('\n') => Err(BadRequest::Malformed("request head too long")),
            Ok(_) => {
                let end = line.trim_end_matches(['\r', '\n']).len();
                line.truncate(end);
                Ok(())
            }
        }
    };
    read(&mut r, &mut line)?;
    let mut parts = line.split(' ');
    let (Some(method), Some(target), Some(version), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err(BadRequest::Malformed("bad request line"));
    };
    if !version.starts_with("HTTP/1.") || !target.starts_with('/') {
        return Err(BadRequest::Malformed("bad request line"));
    }
    if method != "GET" && method != "HEAD" {
        return Err(BadRequest::Method);
    }
    let (path, query) = target.split_once('?').unwrap_or((target, ""));
    let mut request = Request {
        method: method.to_string(),
        path: decode(path).ok_or(BadRequest::Malformed("bad path"))?,
        query: parse_query(query).ok_or(BadRequest::Malformed("bad query"))?,
        headers: Vec::new(),
    };
    loop {
        read(&mut r, &mut line)?;
        if line.is_empty() {
            return Ok(request);
        }
        let (name, value) = line
            .split_once(':')
            .ok_or(BadRequest::Malformed("bad header"))?;
        request
            .headers
            .push((name.trim().to_ascii_lowercase(), value.trim().to_string()));
    }
}

/// The parameters of a query string (`a=1&b=x%20y`), percent-decoded.
pub fn parse_query(q: &str) -> Option<Vec<(String, String)>> {
    q.split('&')
        .filter(|p| !p.is_empty())
        .map(|p| {
            let (k, v) = p.split_once('=').unwrap_or((p, ""));
            Some((decode(k)?, decode(v)?))
        })
        .collect()
}

/// `s` percent-decoded (`+` is a space), or `None` if that is not UTF-8 or a `%` is
/// not followed by two hex digits.
fn decode(s: &str) -> Option<String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut k = 0;
    while k < b.len() {
        match b[k] {
            b'%' => {
                let hex = std::str::from_utf8(b.get(k + 1..k + 3)?).ok()?;
                out.push(u8::from_str_radix(hex, 16).ok()?);
                k += 3;
            }
            b'+' => {
                out.push(b' ');
                k += 1;
            }
            c => {
                out.push(c);
                k += 1;
            }
        }
    }
    String::from_utf8(out).ok()
}

/// The reason phrase of `status`.
fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        409 => "Conflict",
        503 => "Service Unavailable",
        _ => "Error",
    }
}

/// Write `res` to `w` (its body left out for a `HEAD`), with the headers every
/// response has: no caching, no sniffing, no framing, only the page's own resources.
pub fn write_response(mut w: impl Write, res: &Response, head: bool) -> io::Result<()> {
    let mut h = format!(
        "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nConnection: close\r\n\
         Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nX-Frame-Options: DENY\r\n\
         Referrer-Policy: no-referrer\r\nContent-Security-Policy: default-src 'self'; \
         img-src 'self' data: blob:; frame-ancestors 'none'\r\n",
        res.status,
        reason(res.status),
        res.content_type,
        res.body.len()
    );
    for (k, v) in &res.headers {
        h += &format!("{k}: {v}\r\n");
    }
    h += "\r\n";
    w.write_all(h.as_bytes())?;
    if !head {
        w.write_all(&res.body)?;
    }
    w.flush()
}

/// What answers each request.
pub type Handler = dyn Fn(&Request) -> Response + Send + Sync;

/// Serve `listener`'s connections with `handler`, each on a thread of its own, until
/// accepting fails for good.
pub fn serve(listener: TcpListener, handler: Arc<Handler>) -> io::Result<()> {
    let open = Arc::new(AtomicUsize::new(0));
    for stream in listener.incoming() {
        let stream = match stream {
            Ok(s) => s,
            // A connection reset before it was accepted, or out of descriptors for a
            // moment: the next one may do.
            Err(e) => {
                log::debug!("accept: {e}");
                std::thread::sleep(Duration::from_millis(10));
                continue;
            }
        };
        if open.fetch_add(1, Ordering::SeqCst) >= MAX_CONNECTIONS {
            open.fetch_sub(1, Ordering::SeqCst);
            let _ = write_response(&stream, &Response::text(503, "busy\n"), false);
            continue;
        }
        let (handler, open) = (handler.clone(), open.clone());
        let spawned = std::thread::Builder::new()
            .name("view-http".into())
            .spawn(move || {
                if let Err(e) = connection(&stream, &*handler) {
                    log::debug!("connection: {e}");
                }
                open.fetch_sub(1, Ordering::SeqCst);
            });
        if let Err(e) = spawned {
            log::warn!("cannot start a thread for a connection: {e}");
        }
    }
    Ok(())
}

/// Read one request from `stream` and answer it.
fn connection(stream: &TcpStream, handler: &Handler) -> io::Result<()> {
    stream.set_read_timeout(Some(READ_TIMEOUT))?;
    stream.set_write_timeout(Some(Duration::from_secs(30)))?;
    let (res, head) = match read_request(stream) {
        Ok(req) => (handler(&req), req.method == "HEAD"),
        Err(BadRequest::Method) => (Response::text(405, "GET only\n"), false),
        Err(BadRequest::Malformed(why)) => (Response::text(400, format!("{why}\n")), false),
    };
    write_response(stream, &res, head)
}

/// `bytes` in standard base64 with padding.
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            if k <= c.len() {
                out.push(A[(n >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_request_is_its_line_query_and_headers() {
        let raw = "GET /explain?x=3&y=%34&name=a+b HTTP/1.1\r\nHost: localhost:80\r\n\
                   Cookie: a=1; emray=xyz\r\n\r\n";
        let r = read_request(raw.as_bytes()).unwrap();
        assert_eq!(r.path, "/explain");
        assert_eq!(r.param("y"), Some("4"));
        assert_eq!(r.param("name"), Some("a b"));
        assert_eq!(r.header("host"), Some("localhost:80"));
        assert_eq!(r.cookie("emray"), Some("xyz"));
        assert_eq!(r.cookie("b"), None);
    }

    #[test]
    fn malformed_requests_and_other_methods_are_refused() {
        let bad = |s: &str| read_request(s.as_bytes()).unwrap_err();
        assert_eq!(bad("POST / HTTP/1.1\r\n\r\n"), BadRequest::Method);
        assert!(matches!(bad("GET /\r\n\r\n"), BadRequest::Malformed(_)));
        assert!(matches!(
            bad("GET / HTTP/1.1\r\nHost"),
            BadRequest::Malformed(_)
        ));
        assert!(matches!(
            bad("GET /%zz HTTP/1.1\r\n\r\n"),
            BadRequest::Malformed(_)
        ));
        let long = format!("GET /{} HTTP/1.1\r\n\r\n", "a".repeat(20_000));
        assert!(matches!(bad(&long), BadRequest::Malformed(_)));
    }

    #[test]
    fn base64_pads_as_the_standard_does() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
    }
}
