//! Who may use the viewer: a request must carry the session's token (128 random bits,
//! in the `token` query parameter or the cookie the first page load sets) and a `Host`
//! header naming this server (`localhost` or an IP address, with the listening port):
//! another site's page, even one whose name was made to resolve to 127.0.0.1 (DNS
//! rebinding), has neither.

use super::http::Request;
use std::net::IpAddr;

/// The session's secret and the port its `Host` must name.
pub struct Guard {
    token: String,
    port: u16,
}

/// How a request proved itself.
#[derive(Debug, PartialEq, Eq)]
pub enum Access {
    /// With the token in its query (the page then sets the cookie).
    Query,
    /// With the cookie.
    Cookie,
}

/// Why a request is refused (answered 403).
#[derive(Debug, PartialEq, Eq)]
pub enum Refusal {
    /// No `Host`, or one that is not this server.
    Host,
    /// No token, or the wrong one.
    Token,
}

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Refusal::Host => "forbidden: the Host header does not name this server\n",
            Refusal::Token => "forbidden: open the URL emray view printed (with its token)\n",
        })
    }
}

impl Guard {
    /// A guard with a fresh random token, for a server on `port`.
    pub fn new(port: u16) -> Result<Guard, getrandom::Error> {
        let mut bytes = [0u8; 16];
        getrandom::fill(&mut bytes)?;
        Ok(Guard::with_token(
            bytes.iter().map(|b| format!("{b:02x}")).collect(),
            port,
        ))
    }

    fn with_token(token: String, port: u16) -> Guard {
        Guard { token, port }
    }

    /// The token, for the URL printed.
    pub fn token(&self) -> &str {
        &self.token
    }

    /// The cookie's name (by port: browsers share cookies between a host's ports).
    pub fn cookie_name(&self) -> String {
        format!("emray_view_{}", self.port)
    }

    /// The `Set-Cookie` value a page load with the token answers with.
    pub fn set_cookie(&self) -> String {
        format!(
            "{}={}; Path=/; HttpOnly; SameSite=Strict",
            self.cookie_name(),
            self.token
        )
    }

    /// Whether `req` may be answered, and how it proved it.
    pub fn check(&self, req: &Request) -> Result<Access, Refusal> {
        if !req.header("host").is_some_and(|h| self.is_own_host(h)) {
            return Err(Refusal::Host);
        }
        if req.param("token").is_some_and(|t| same(t, &self.token)) {
            return Ok(Access::Query);
        }
        if req
            .cookie(&self.cookie_name())
            .is_some_and(|t| same(t, &self.token))
        {
            return Ok(Access::Cookie);
        }
        Err(Refusal::Token)
    }

    /// Whether `host` is `localhost` or an IP address (never a name that could be
    /// rebound), with this server's port.
    fn is_own_host(&self, host: &str) -> bool {
        let Some((name, port)) = host.rsplit_once(':') else {
            return false;
        };
        if port.parse::<u16>() != Ok(self.port) {
            return false;
        }
        let name = name
            .strip_prefix('[')
            .and_then(|n| n.strip_suffix(']'))
            .unwrap_or(name);
        name.eq_ignore_ascii_case("localhost") || name.parse::<IpAddr>().is_ok()
    }
}

/// `a == b`, in a time that does not depend on where they first differ.
fn same(a: &str, b: &str) -> bool {
    a.len() == b.len() && a.bytes().zip(b.bytes()).fold(0u8, |d, (x, y)| d | (x ^ y)) == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(host: Option<&str>, query: &str, cookie: Option<&str>) -> Request {
        let mut headers = Vec::new();
        if let Some(h) = host {
            headers.push(("host".to_string(), h.to_string()));
        }
        if let Some(c) = cookie {
            headers.push(("cookie".to_string(), c.to_string()));
        }
        Request {
            method: "GET".into(),
            path: "/".into(),
            query: super::super::http::parse_query(query).unwrap(),
            headers,
        }
    }

    #[test]
    fn the_token_in_the_query_or_the_cookie_lets_a_request_in() {
        let g = Guard::with_token("abc123".into(), 8080);
        let ok = Some("127.0.0.1:8080");
        assert_eq!(
            g.check(&request(ok, "token=abc123", None)),
            Ok(Access::Query)
        );
        let cookie = "x=1; emray_view_8080=abc123";
        assert_eq!(g.check(&request(ok, "", Some(cookie))), Ok(Access::Cookie));
        assert_eq!(
            g.check(&request(ok, "token=abc124", None)),
            Err(Refusal::Token)
        );
        assert_eq!(g.check(&request(ok, "", None)), Err(Refusal::Token));
        let other_port = "emray_view_8081=abc123";
        assert_eq!(
            g.check(&request(ok, "", Some(other_port))),
            Err(Refusal::Token)
        );
    }

    #[test]
    fn only_localhost_or_an_address_with_the_port_is_a_host() {
        let g = Guard::with_token("t".into(), 8080);
        for host in [
            "localhost:8080",
            "127.0.0.1:8080",
            "[::1]:8080",
            "10.0.0.2:8080",
        ] {
            assert_eq!(
                g.check(&request(Some(host), "token=t", None)),
                Ok(Access::Query)
            );
        }
        for host in [
            "evil.example:8080",
            "127.0.0.1:8081",
            "localhost",
            "127.0.0.1",
        ] {
            let r = g.check(&request(Some(host), "token=t", None));
            assert_eq!(r, Err(Refusal::Host), "{host}");
        }
        assert_eq!(g.check(&request(None, "token=t", None)), Err(Refusal::Host));
    }

    #[test]
    fn tokens_are_128_random_bits() {
        let (a, b) = (Guard::new(1).unwrap(), Guard::new(1).unwrap());
        assert_eq!(a.token().len(), 32);
        assert_ne!(a.token(), b.token());
    }
}
