//! Time spent per phase of a simplification, for `SPLITSTREAM_DEBUG`.

/// Time spent per phase over the whole simplification, printed under
/// `SPLITSTREAM_DEBUG`.
#[derive(Default)]
pub(super) struct Phases {
    at: Option<std::time::Instant>,
    seconds: Vec<(&'static str, f64)>,
}

impl Phases {
    /// Charges the time since the last lap to `name`.
    pub(super) fn lap(&mut self, name: &'static str) {
        let now = std::time::Instant::now();
        if let Some(at) = self.at {
            let dt = (now - at).as_secs_f64();
            match self.seconds.iter_mut().find(|(n, _)| *n == name) {
                Some((_, s)) => *s += dt,
                None => self.seconds.push((name, dt)),
            }
        }
        self.at = Some(now);
    }

    pub(super) fn report(&self) -> String {
        let total: f64 = self.seconds.iter().map(|(_, s)| s).sum();
        let parts: Vec<String> = self
            .seconds
            .iter()
            .map(|(n, s)| format!("{n} {:.0}", s * 1e3))
            .collect();
        format!(
            "simplify phases, ms (total {:.0}): {}",
            total * 1e3,
            parts.join(", ")
        )
    }
}
