//! Lights in time: how a point light's emission varies over its own proper time (the time of
//! the frame it rests in), read from a light's or the camera flash's `pulse`, `on` or `table`
//! (docs/physics.md §12.2).

use super::doc::{Node, Val};
use super::reader::{SceneResult, Table};

/// How a light's emission varies over its proper time: a factor on its intensity.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub enum Timing {
    /// Always on (factor 1).
    Steady,
    /// A Gaussian pulse peaking at 1 at proper time `at`, `width` its full width at half
    /// maximum.
    Pulse {
        /// The peak's proper time.
        at: f64,
        /// The full width at half maximum.
        width: f64,
    },
    /// On (factor 1) within the closed intervals `[start, end]`, off between them.
    On(Vec<[f64; 2]>),
    /// Factors at proper times (times increasing), linear between them; the first and last
    /// factors hold before and after.
    Table(Vec<[f64; 2]>),
}

impl Timing {
    /// The factor on the light's intensity at proper time `tau`.
    pub fn factor(&self, tau: f64) -> f64 {
        match self {
            Timing::Steady => 1.0,
            Timing::Pulse { at, width } => {
                // FWHM = 2 √(2 ln 2) σ, so (τ − at)² / 2σ² = 4 ln 2 ((τ − at) / FWHM)².
                let x = (tau - at) / width;
                (-4.0 * std::f64::consts::LN_2 * x * x).exp()
            }
            Timing::On(spans) => {
                // Sorted and disjoint (`read` merges them): the last span starting by tau.
                let i = spans.partition_point(|s| s[0] <= tau);
                let on = i > 0 && tau <= spans[i - 1][1];
                f64::from(u8::from(on))
            }
            Timing::Table(rows) => {
                let i = rows.partition_point(|r| r[0] <= tau);
                match (i, rows.len()) {
                    (0, _) => rows[0][1],
                    (i, n) if i == n => rows[n - 1][1],
                    (i, _) => {
                        let ([t0, f0], [t1, f1]) = (rows[i - 1], rows[i]);
                        f0 + (f1 - f0) * (tau - t0) / (t1 - t0)
                    }
                }
            }
        }
    }

    /// Whether the emission never changes.
    pub fn is_steady(&self) -> bool {
        matches!(self, Timing::Steady)
    }

    /// The same timing `dt` later.
    pub fn delayed(&self, dt: f64) -> Timing {
        match self {
            Timing::Steady => Timing::Steady,
            Timing::Pulse { at, width } => Timing::Pulse {
                at: at + dt,
                width: *width,
            },
            Timing::On(spans) => Timing::On(spans.iter().map(|&[a, b]| [a + dt, b + dt]).collect()),
            Timing::Table(rows) => Timing::Table(rows.iter().map(|&[t, f]| [t + dt, f]).collect()),
        }
    }
}

/// The keys [`read`] reads.
pub(crate) const TIMING_KEYS: [&str; 3] = ["pulse", "on", "table"];

/// The timing a light's table gives (at most one of `pulse`, `on` and `table`; none: steady).
pub(crate) fn read(t: &Table) -> SceneResult<Timing> {
    let given: Vec<&str> = TIMING_KEYS.into_iter().filter(|k| t.has(k)).collect();
    if given.len() > 1 {
        return Err(t.error(
            given[1],
            format!(
                "give one of pulse, on and table, not {}",
                given.join(" and ")
            ),
        ));
    }
    if let Some(p) = t.table("pulse")? {
        let at = p.f64_or("at", 0.0)?;
        let width = p.f64_where(
            "width",
            None,
            |w| w > 0.0,
            "greater than 0: the pulse's full width at half maximum, in the light's proper time",
        )?;
        p.finish(&["at", "width"])?;
        return Ok(Timing::Pulse { at, width });
    }
    if let Some(n) = t.get("on") {
        let spans = pairs(t, n, "on", "[start, end]")?;
        if let Some(i) = spans.iter().position(|&[a, b]| a >= b) {
            let [a, b] = spans[i];
            return Err(t.error_at(
                n,
                "on",
                format!(
                    "interval {} is [{a}, {b}]: its start must be before its end",
                    i + 1
                ),
            ));
        }
        return Ok(Timing::On(disjoint(spans)));
    }
    if let Some(n) = t.get("table") {
        let rows = pairs(t, n, "table", "[time, factor]")?;
        if let Some(i) = rows.windows(2).position(|w| w[1][0] <= w[0][0]) {
            return Err(t.error_at(
                n,
                "table",
                format!(
                    "row {} must come after row {} in time (times increasing)",
                    i + 2,
                    i + 1
                ),
            ));
        }
        if let Some(i) = rows.iter().position(|r| r[1] < 0.0) {
            return Err(t.error_at(
                n,
                "table",
                format!(
                    "row {}'s factor is {}: factors are 0 or more",
                    i + 1,
                    rows[i][1]
                ),
            ));
        }
        return Ok(Timing::Table(rows));
    }
    Ok(Timing::Steady)
}

/// Intervals sorted by their starts, overlapping ones joined: so a time finds its interval by
/// a binary search, however many there are.
fn disjoint(mut spans: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    spans.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(spans.len());
    for s in spans {
        match out.last_mut() {
            Some(last) if s[0] <= last[1] => last[1] = last[1].max(s[1]),
            _ => out.push(s),
        }
    }
    out
}

/// A non-empty array of pairs of numbers.
fn pairs(t: &Table, n: &Node, key: &str, what: &str) -> SceneResult<Vec<[f64; 2]>> {
    let Val::Array(items) = &n.val else {
        return Err(t.error_at(
            n,
            key,
            format!("expected an array of {what} pairs, found {}", n.kind()),
        ));
    };
    if items.is_empty() {
        return Err(t.error_at(n, key, format!("expected at least one {what} pair")));
    }
    items
        .iter()
        .map(|e| {
            let v = t.numbers_of(e, key, Some(2))?;
            Ok([v[0], v[1]])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::Timing;

    #[test]
    fn pulse_is_half_at_half_its_width() {
        let p = Timing::Pulse {
            at: 3.0,
            width: 0.4,
        };
        assert_eq!(p.factor(3.0), 1.0);
        assert!((p.factor(3.2) - 0.5).abs() < 1e-15);
        assert!((p.factor(2.8) - 0.5).abs() < 1e-15);
        assert_eq!(p.delayed(1.0).factor(4.2), p.factor(3.2));
    }

    #[test]
    fn intervals_and_tables() {
        let on = Timing::On(super::disjoint(vec![[3.0, 4.0], [0.0, 1.0], [0.5, 0.8]]));
        assert_eq!(on, Timing::On(vec![[0.0, 1.0], [3.0, 4.0]]));
        let at = |t: f64| on.factor(t);
        assert_eq!((at(4.0), at(4.5)), (1.0, 0.0));
        let joined = super::disjoint(vec![[0.0, 2.0], [1.0, 3.0], [3.0, 5.0], [6.0, 7.0]]);
        assert_eq!(joined, vec![[0.0, 5.0], [6.0, 7.0]]);
        assert_eq!(
            (at(-0.1), at(0.0), at(1.0), at(2.0), at(3.5)),
            (0.0, 1.0, 1.0, 0.0, 1.0)
        );
        let table = Timing::Table(vec![[0.0, 0.0], [1.0, 2.0], [3.0, 0.0]]);
        let f = |t: f64| table.factor(t);
        assert_eq!(
            (f(-5.0), f(0.5), f(1.0), f(2.0), f(9.0)),
            (0.0, 1.0, 2.0, 1.0, 0.0)
        );
    }
}
