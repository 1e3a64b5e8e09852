//! Who may use the viewer: every request must carry the access token, name a host the server
//! answers to (a DNS-rebinding page names its own domain) and, if it says where it comes from,
//! come from that same host. Anything else is 403, before any other work.

use std::net::IpAddr;

/// The checks a request passes before anything else.
#[derive(Clone, Debug)]
pub(crate) struct Access {
    token: String,
    /// Host names (without port) the server answers to besides IP literals and `localhost`.
    names: Vec<String>,
}

/// Why a request is refused (the body of the 403).
pub(crate) type Refusal = &'static str;

impl Access {
    /// `token`: the random token every request must carry; `names`: the host names besides IP
    /// literals and `localhost` that may appear in Host (the machine's own name, `--allow-host`).
    pub fn new(token: String, names: Vec<String>) -> Access {
        let names = names.into_iter().map(|n| n.to_ascii_lowercase()).collect();
        Access { token, names }
    }

    pub fn token(&self) -> &str {
        &self.token
    }

    /// Whether a request with this query string and these Host and Origin headers may go on.
    pub fn check(
        &self,
        query: &str,
        host: Option<&str>,
        origin: Option<&str>,
    ) -> Result<(), Refusal> {
        let host = host.ok_or("no Host header")?;
        if !self.host_allowed(host) {
            return Err("this server does not answer to that Host (see --allow-host)");
        }
        if let Some(origin) = origin {
            // Same origin only: http:// and exactly the Host the request names.
            let same = origin
                .strip_prefix("http://")
                .is_some_and(|o| o.eq_ignore_ascii_case(host));
            if !same {
                return Err("requests from another origin are refused");
            }
        }
        let given = query_value(query, "token")
            .ok_or("no access token: open the URL the server printed")?;
        if !constant_time_eq(given.as_bytes(), self.token.as_bytes()) {
            return Err("wrong access token");
        }
        Ok(())
    }

    /// An IP literal, `localhost`, or a name given; any port (an SSH tunnel may move it).
    fn host_allowed(&self, host: &str) -> bool {
        let name = match host.strip_prefix('[') {
            // [v6]:port
            Some(rest) => match rest.split_once(']') {
                Some((v6, tail)) if tail.is_empty() || valid_port(tail) => {
                    return v6.parse::<std::net::Ipv6Addr>().is_ok()
                }
                _ => return false,
            },
            None => match host.rsplit_once(':') {
                Some((name, port)) if valid_port(&format!(":{port}")) => name,
                Some(_) => return false,
                None => host,
            },
        };
        let name = name.to_ascii_lowercase();
        name.parse::<IpAddr>().is_ok() || name == "localhost" || self.names.contains(&name)
    }
}

fn valid_port(tail: &str) -> bool {
    tail.strip_prefix(':')
        .is_some_and(|p| !p.is_empty() && p.len() <= 5 && p.bytes().all(|b| b.is_ascii_digit()))
}

/// The value of `key` in a query string (`a=1&b=2`), percent-decoded; None if absent or badly
/// encoded.
pub(crate) fn query_value(query: &str, key: &str) -> Option<String> {
    query
        .split('&')
        .filter_map(|kv| kv.split_once('='))
        .find(|(k, _)| *k == key)
        .and_then(|(_, v)| percent_decode(v))
}

/// `%XX` and `+` decoded; None for a bad escape or a result that is not UTF-8.
pub(crate) fn percent_decode(s: &str) -> Option<String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'%' => {
                let hex = b.get(i + 1..i + 3)?;
                if !hex.iter().all(u8::is_ascii_hexdigit) {
                    return None;
                }
                let hex = std::str::from_utf8(hex).ok()?;
                out.push(u8::from_str_radix(hex, 16).ok()?);
                i += 3;
            }
            b'+' => {
                out.push(b' ');
                i += 1;
            }
            c => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8(out).ok()
}

/// Compare without stopping at the first difference, so that the time taken does not tell how
/// much of a guessed token was right.
fn constant_time_eq(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
}

/// A fresh token: 128 random bits from the operating system, in hex.
pub(crate) fn new_token() -> crate::Result<String> {
    let mut bytes = [0u8; 16];
    getrandom::fill(&mut bytes)
        .map_err(|e| crate::Error::flag("view", format!("no random numbers for a token: {e}")))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn access() -> Access {
        Access::new("abc123".into(), vec!["Node17".into()])
    }

    #[test]
    fn the_token_the_host_and_the_origin_are_checked() {
        let a = access();
        let ok = |q: &str, h: Option<&str>, o: Option<&str>| a.check(q, h, o).is_ok();
        assert!(ok("token=abc123", Some("127.0.0.1:8000"), None));
        assert!(ok(
            "x=1&token=abc123",
            Some("localhost:9"),
            Some("http://localhost:9")
        ));
        assert!(ok("token=abc123", Some("[::1]:8000"), None));
        assert!(ok("token=abc123", Some("node17:8000"), None));
        assert!(ok("token=abc123", Some("10.0.0.5"), None));
        // No token, a wrong one, a prefix of it, one with more.
        assert!(!ok("", Some("127.0.0.1:8000"), None));
        assert!(!ok("token=abc124", Some("127.0.0.1:8000"), None));
        assert!(!ok("token=abc12", Some("127.0.0.1:8000"), None));
        assert!(!ok("token=abc1234", Some("127.0.0.1:8000"), None));
        // DNS rebinding: a name the server does not answer to, however it is written.
        assert!(!ok("token=abc123", Some("evil.example:8000"), None));
        assert!(!ok("token=abc123", Some("127.0.0.1.evil.example"), None));
        assert!(!ok("token=abc123", Some("localhost:80:80"), None));
        assert!(!ok("token=abc123", Some("[::1]x"), None));
        assert!(!ok("token=abc123", None, None));
        // Another origin, or https, or a null origin.
        assert!(!ok(
            "token=abc123",
            Some("127.0.0.1:8000"),
            Some("http://evil.example")
        ));
        assert!(!ok(
            "token=abc123",
            Some("127.0.0.1:8000"),
            Some("http://127.0.0.1:8001")
        ));
        assert!(!ok(
            "token=abc123",
            Some("127.0.0.1:8000"),
            Some("https://127.0.0.1:8000")
        ));
        assert!(!ok("token=abc123", Some("127.0.0.1:8000"), Some("null")));
    }

    #[test]
    fn queries_are_decoded() {
        assert_eq!(query_value("a=1&b=x%2Fy+z", "b").as_deref(), Some("x/y z"));
        assert_eq!(query_value("a=1", "b"), None);
        assert_eq!(query_value("b=%zz", "b"), None);
        assert_eq!(query_value("b=%ff", "b"), None);
        assert_eq!(query_value("b=%+f", "b"), None);
        assert_eq!(new_token().unwrap().len(), 32);
        assert_ne!(new_token().unwrap(), new_token().unwrap());
    }
}
