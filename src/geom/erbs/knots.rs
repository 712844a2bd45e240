//! One ERBS parameter direction: knots, open or closed, and the domain actually used.
//!
//! Open, n local curves: knots t_0 … t_{n+1} with t_0 = t_1 and t_n = t_{n+1}, strictly
//! increasing in between. Local l is centred at c_l = t_{l+1} and supported on [t_l, t_{l+2}].
//!
//! Closed (periodic), n local curves: knots k_0 < … < k_n, period T = k_n − k_0. Local l is
//! centred at c_l = k_l and supported on [c_{l−1}, c_{l+1}], with c_{−1} = k_{n−1} − T; local 0
//! also serves the last interval [k_{n−1}, k_n], shifted by T.
//!
//! Either way interval i is [c_i, c_{i+1}] and blends local i (weight 1 − B) with local
//! i + 1 (mod n, weight B). The domain is [c_0, c_{n−1}] (open) or [k_0, k_n] (closed), or a
//! window inside it: a local ERBS curve restricted exactly to a shorter support keeps its knots
//! and narrows its domain.

use super::super::error::{GeomError, GeomResult};

/// What the locals of a direction are, for messages: a surface's are patches.
#[derive(Debug, Clone, Copy)]
enum Locals {
    Curves,
    Patches,
}

impl Locals {
    fn noun(self) -> &'static str {
        match self {
            Locals::Curves => "local curves",
            Locals::Patches => "local patches",
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct ErbsKnots {
    knots: Vec<f64>,
    closed: bool,
    domain: (f64, f64),
}

impl ErbsKnots {
    /// Open knots for `n` local curves.
    pub fn open(knots: Vec<f64>, n: usize) -> GeomResult<Self> {
        Self::open_of(knots, n, Locals::Curves)
    }

    /// Open knots for one direction of `n` local patches (errors say patches).
    pub fn open_patches(knots: Vec<f64>, n: usize) -> GeomResult<Self> {
        Self::open_of(knots, n, Locals::Patches)
    }

    /// Closed knots for one direction of `n` local patches (errors say patches).
    pub fn closed_patches(knots: Vec<f64>, n: usize) -> GeomResult<Self> {
        Self::closed_of(knots, n, Locals::Patches)
    }

    fn open_of(knots: Vec<f64>, n: usize, locals: Locals) -> GeomResult<Self> {
        let locals = locals.noun();
        if n < 2 {
            return Err(GeomError::new(
                "local",
                format!("an ERBS needs at least 2 {locals}, got {n}"),
            ));
        }
        if knots.len() != n + 2 {
            return Err(GeomError::new(
                "knots",
                format!(
                    "expected {} knots ({locals} + 2 = {n} + 2), got {}",
                    n + 2,
                    knots.len()
                ),
            ));
        }
        check_finite(&knots)?;
        if knots[0] != knots[1] {
            return Err(GeomError::new(
                "knots",
                format!("knot 0 ({}) must equal knot 1 ({})", knots[0], knots[1]),
            ));
        }
        if knots[n] != knots[n + 1] {
            return Err(GeomError::new(
                "knots",
                format!(
                    "knot {} ({}) must equal knot {n} ({})",
                    n + 1,
                    knots[n + 1],
                    knots[n]
                ),
            ));
        }
        check_increasing(&knots, 2..=n)?;
        let domain = (knots[1], knots[n]);
        Ok(Self {
            knots,
            closed: false,
            domain,
        })
    }

    /// Closed (periodic) knots for `n` local curves: n + 1 strictly increasing values.
    pub fn closed(knots: Vec<f64>, n: usize) -> GeomResult<Self> {
        Self::closed_of(knots, n, Locals::Curves)
    }

    fn closed_of(knots: Vec<f64>, n: usize, locals: Locals) -> GeomResult<Self> {
        let locals = locals.noun();
        if n < 2 {
            return Err(GeomError::new(
                "local",
                format!("a closed ERBS needs at least 2 {locals}, got {n}"),
            ));
        }
        if knots.len() != n + 1 {
            return Err(GeomError::new(
                "knots",
                format!(
                    "expected {} knots for a closed ERBS ({locals} + 1 = {n} + 1, the last closing the period), got {}",
                    n + 1,
                    knots.len()
                ),
            ));
        }
        check_finite(&knots)?;
        check_increasing(&knots, 1..=n)?;
        let domain = (knots[0], knots[n]);
        Ok(Self {
            knots,
            closed: true,
            domain,
        })
    }

    /// Uniform knots over [a, b] for `n` locals: open t_1 = a … t_n = b, closed k_0 = a … k_n = b.
    pub fn uniform(a: f64, b: f64, n: usize, closed: bool) -> GeomResult<Self> {
        Self::uniform_of(a, b, n, closed, Locals::Curves)
    }

    /// [`ErbsKnots::uniform`] for one direction of `n` local patches (errors say patches).
    pub fn uniform_patches(a: f64, b: f64, n: usize, closed: bool) -> GeomResult<Self> {
        Self::uniform_of(a, b, n, closed, Locals::Patches)
    }

    fn uniform_of(a: f64, b: f64, n: usize, closed: bool, locals: Locals) -> GeomResult<Self> {
        if !(a.is_finite() && b.is_finite() && a < b) {
            return Err(GeomError::new(
                "from",
                format!("the source's domain [{a}, {b}] is not a finite interval"),
            ));
        }
        let steps = if closed {
            n
        } else {
            n.saturating_sub(1).max(1)
        };
        let at = |i: usize| {
            if i >= steps {
                b
            } else {
                a + (b - a) * (i as f64 / steps as f64)
            }
        };
        if closed {
            Self::closed_of((0..=n).map(at).collect(), n, locals)
        } else {
            let mut k: Vec<f64> = (0..n).map(at).collect();
            k.insert(0, a);
            k.push(b);
            Self::open_of(k, n, locals)
        }
    }

    /// The same knots used only on `[a, b]` (inside the full domain): an exact restriction.
    pub fn with_domain(mut self, (a, b): (f64, f64)) -> GeomResult<Self> {
        let (lo, hi) = self.full_domain();
        if !(a.is_finite() && b.is_finite() && lo <= a && a < b && b <= hi) {
            return Err(GeomError::new(
                "domain",
                format!("[{a}, {b}] is not a non-empty interval inside the knots' [{lo}, {hi}]"),
            ));
        }
        self.domain = (a, b);
        Ok(self)
    }

    /// Every knot and the domain mapped by an increasing affine `f` (a reparametrisation).
    pub(crate) fn map(&mut self, f: &impl Fn(f64) -> f64) {
        for k in &mut self.knots {
            *k = f(*k);
        }
        self.domain = (f(self.domain.0), f(self.domain.1));
    }

    #[must_use]
    pub fn as_slice(&self) -> &[f64] {
        &self.knots
    }

    #[must_use]
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// Number of local curves.
    #[must_use]
    pub fn locals(&self) -> usize {
        if self.closed {
            self.knots.len() - 1
        } else {
            self.knots.len() - 2
        }
    }

    #[must_use]
    pub fn domain(&self) -> (f64, f64) {
        self.domain
    }

    /// The domain without a window: [c_0, c_{n−1}] or [k_0, k_n].
    #[must_use]
    pub fn full_domain(&self) -> (f64, f64) {
        let n = self.locals();
        if self.closed {
            (self.knots[0], self.knots[n])
        } else {
            (self.knots[1], self.knots[n])
        }
    }

    /// The period T of a closed direction.
    #[must_use]
    pub fn period(&self) -> Option<f64> {
        self.closed
            .then(|| self.knots[self.knots.len() - 1] - self.knots[0])
    }

    /// Centre c_i of local i; for closed knots c_n = k_n (the period's end).
    #[must_use]
    pub fn centre(&self, i: usize) -> f64 {
        if self.closed {
            self.knots[i]
        } else {
            self.knots[i + 1]
        }
    }

    /// Number of intervals: n − 1 open, n closed.
    #[must_use]
    pub fn intervals(&self) -> usize {
        if self.closed {
            self.locals()
        } else {
            self.locals() - 1
        }
    }

    /// Interval i = [c_i, c_{i+1}].
    #[must_use]
    pub fn interval(&self, i: usize) -> (f64, f64) {
        (self.centre(i), self.centre(i + 1))
    }

    /// The local blended in with weight B on interval i, and the shift its parameter takes there
    /// (T where a closed direction wraps to local 0).
    #[must_use]
    pub fn right(&self, i: usize) -> (usize, f64) {
        let n = self.locals();
        match self.period() {
            Some(t) if i + 1 == n => (0, t),
            _ => (i + 1, 0.0),
        }
    }

    /// The interval holding t (clamped to the domain); an interior knot belongs to the interval
    /// to its right, the domain's end to the last interval.
    #[must_use]
    pub fn locate(&self, t: f64) -> usize {
        let t = t.clamp(self.domain.0, self.domain.1);
        let last = self.intervals() - 1;
        // Centres c_1 … c_last ≤ t.
        let mut lo = 0;
        let mut hi = last;
        while lo < hi {
            let mid = (lo + hi).div_ceil(2);
            if self.centre(mid) <= t {
                lo = mid;
            } else {
                hi = mid - 1;
            }
        }
        lo
    }

    /// Support of local l, unwrapped: [c_{l−1}, c_{l+1}] (open ends at t_0 and t_{n+1}).
    #[must_use]
    pub fn support(&self, l: usize) -> (f64, f64) {
        let n = self.locals();
        if self.closed {
            let t = self.period().unwrap_or(0.0);
            let lo = if l == 0 {
                self.knots[n - 1] - t
            } else {
                self.knots[l - 1]
            };
            (lo, self.knots[l + 1])
        } else {
            (self.knots[l], self.knots[l + 2])
        }
    }

    /// The knots with `t` inserted strictly inside interval i (and inside the domain): t becomes
    /// the centre of a new local i + 1. Returns the interval index.
    pub fn insert(&self, t: f64) -> GeomResult<(ErbsKnots, usize)> {
        let (a, b) = self.domain;
        if !(t > a && t < b) {
            return Err(GeomError::new(
                "insert_knot",
                format!("parameter {t} is not inside the open domain ({a}, {b})"),
            ));
        }
        let i = self.locate(t);
        let (lo, hi) = self.interval(i);
        if t <= lo || t >= hi {
            return Err(GeomError::new(
                "insert_knot",
                format!("parameter {t} is a knot: refinement inserts strictly between knots"),
            ));
        }
        let mut knots = self.knots.clone();
        // Centre c_{i+1} sits at index i + 1 (closed) or i + 2 (open).
        let at = if self.closed { i + 1 } else { i + 2 };
        knots.insert(at, t);
        Ok((
            ErbsKnots {
                knots,
                closed: self.closed,
                domain: self.domain,
            },
            i,
        ))
    }
}

fn check_finite(knots: &[f64]) -> GeomResult<()> {
    match knots.iter().position(|t| !t.is_finite()) {
        Some(i) => Err(GeomError::new(
            "knots",
            format!("knot {i} is {}, not a finite number", knots[i]),
        )),
        None => Ok(()),
    }
}

fn check_increasing(knots: &[f64], range: std::ops::RangeInclusive<usize>) -> GeomResult<()> {
    for i in range {
        if knots[i] <= knots[i - 1] {
            return Err(GeomError::new(
                "knots",
                format!(
                    "knot {i} ({}) must be greater than knot {} ({}): interior ERBS knots are strictly increasing",
                    knots[i],
                    i - 1,
                    knots[i - 1]
                ),
            ));
        }
    }
    Ok(())
}
