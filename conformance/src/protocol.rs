//! The decoder protocol (conformance/README.md): what a decoder under test
//! prints, how it is parsed, and how it is judged against a vector.

use crate::manifest::{Vector, hex};

/// What a decoder reported for one stream.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Outcome {
    /// State hashes in the order reported.
    pub hashes: Vec<u64>,
    pub verdict: Verdict,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// `ok`: the stream decoded.
    Ok,
    /// `error <class>`: the stream was rejected.
    Error(String),
    /// The decoder broke the protocol: crashed, timed out, printed garbage
    /// or nothing.
    Broken(String),
}

impl Outcome {
    pub fn broken(why: impl Into<String>) -> Outcome {
        Outcome {
            hashes: Vec::new(),
            verdict: Verdict::Broken(why.into()),
        }
    }

    /// The protocol text for this outcome (what `splitstream-conformance
    /// decode` prints).
    pub fn to_protocol(&self) -> String {
        let mut s = String::new();
        for &h in &self.hashes {
            s.push_str(&hex(h));
            s.push('\n');
        }
        match &self.verdict {
            Verdict::Ok => s.push_str("ok\n"),
            Verdict::Error(class) => {
                s.push_str("error ");
                s.push_str(class);
                s.push('\n');
            }
            Verdict::Broken(why) => {
                s.push_str("error internal: ");
                s.push_str(why);
                s.push('\n');
            }
        }
        s
    }
}

fn is_hash(line: &str) -> bool {
    line.len() == 16
        && line
            .bytes()
            .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
}

/// Parses a decoder's standard output. Lines end in `\n` (a `\r` before it
/// is tolerated); empty lines are ignored; after the verdict line nothing
/// else may follow.
pub fn parse_output(stdout: &[u8]) -> Outcome {
    let Ok(text) = std::str::from_utf8(stdout) else {
        return Outcome::broken("output is not UTF-8");
    };
    let mut hashes = Vec::new();
    let mut verdict = None;
    for line in text.lines() {
        let line = line.trim_end_matches('\r');
        if line.is_empty() {
            continue;
        }
        if verdict.is_some() {
            return Outcome {
                hashes,
                verdict: Verdict::Broken(format!("output after the verdict: {}", clip(line))),
            };
        }
        if is_hash(line) {
            hashes.push(u64::from_str_radix(line, 16).expect("16 hex digits"));
        } else if line == "ok" {
            verdict = Some(Verdict::Ok);
        } else if let Some(class) = line.strip_prefix("error ") {
            verdict = Some(Verdict::Error(class.trim().to_string()));
        } else {
            return Outcome {
                hashes,
                verdict: Verdict::Broken(format!("unexpected line: {}", clip(line))),
            };
        }
    }
    Outcome {
        hashes,
        verdict: verdict.unwrap_or_else(|| Verdict::Broken("no `ok` or `error` line".into())),
    }
}

fn clip(s: &str) -> String {
    if s.chars().count() > 60 {
        let mut t: String = s.chars().take(60).collect();
        t.push('…');
        t
    } else {
        s.to_string()
    }
}

/// What the vector expects, as shown in the runner's table.
pub fn expected(v: &Vector) -> String {
    if v.valid {
        format!("ok, {} hashes", v.round_hashes.len())
    } else {
        format!("error {}", v.error_class.as_deref().unwrap_or("?"))
    }
}

/// Judges an outcome: `(passed, what was got)`.
pub fn judge(v: &Vector, o: &Outcome) -> (bool, String) {
    let want: Vec<&str> = v.round_hashes.iter().map(String::as_str).collect();
    let got: Vec<String> = o.hashes.iter().map(|&h| hex(h)).collect();
    let first_difference = got.iter().zip(&want).position(|(g, w)| g != w);
    let describe = |verdict: &str| format!("{verdict}, {} hashes", got.len());
    match &o.verdict {
        Verdict::Broken(why) => (false, format!("broken: {why}")),
        Verdict::Ok if !v.valid => (false, describe("ok")),
        Verdict::Ok => {
            if let Some(i) = first_difference {
                (false, format!("ok, hash {i} differs ({})", got[i]))
            } else if got.len() != want.len() {
                (false, describe("ok"))
            } else {
                (true, describe("ok"))
            }
        }
        Verdict::Error(class) => {
            let text = format!("error {class}");
            if v.valid {
                return (false, describe(&text));
            }
            if let Some(i) = first_difference {
                return (false, format!("{text}, hash {i} differs ({})", got[i]));
            }
            if got.len() > want.len() {
                return (
                    false,
                    format!(
                        "{text}, {} hashes (at most {} expected)",
                        got.len(),
                        want.len()
                    ),
                );
            }
            (
                v.error_class.as_deref() == Some(class.as_str()),
                describe(&text),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_three_line_kinds() {
        let o = parse_output(b"00000000000000ff\r\n0123456789abcdef\nok\n\n");
        assert_eq!(o.hashes, vec![0xff, 0x0123_4567_89ab_cdef]);
        assert_eq!(o.verdict, Verdict::Ok);
        let o = parse_output(b"error truncated\n");
        assert_eq!(o.verdict, Verdict::Error("truncated".into()));
        assert!(matches!(parse_output(b"").verdict, Verdict::Broken(_)));
        assert!(matches!(
            parse_output(b"0123\nok\n").verdict,
            Verdict::Broken(_)
        ));
        assert!(matches!(
            parse_output(b"ok\nok\n").verdict,
            Verdict::Broken(_)
        ));
        assert!(matches!(
            parse_output(b"ABCDEF0123456789\nok\n").verdict,
            Verdict::Broken(_)
        ));
    }

    #[test]
    fn round_trips_through_the_text_form() {
        let o = Outcome {
            hashes: vec![1, 2],
            verdict: Verdict::Error("malformed".into()),
        };
        assert_eq!(parse_output(o.to_protocol().as_bytes()), o);
    }
}
