//! The cost of the ray tree, bounded: a primary sample may spawn at most `render.max_rays`
//! secondary rays (reflected and refracted rays at every depth), so no scene is exponential in
//! `max_depth` (two facing half-mirrors, half-glass, double the rays at every bounce).
//!
//! The rule (docs/scene-format.md, `max_rays`): where the budget holds every ray the tree below
//! a hit can spawn, every branch gets what it can use, and the render is the full tree's. Where
//! it does not, the budget is split between the reflected and the refracted branch in
//! proportion to their weights (the light each carries, `reflect` and `transmit` after Fresnel),
//! each followed branch costing one ray; with one ray left, only the stronger branch is
//! followed. The weakest contributions are the ones left out, and the choice is deterministic.

/// What the tree below a hit may still spend: its depth, and the secondary rays its branches
/// and their descendants may spawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Budget {
    /// Bounces so far (0 at the primary hit).
    pub depth: u32,
    /// Secondary rays the tree below may spawn.
    pub rays: u64,
}

impl Budget {
    /// A primary hit's budget.
    pub fn primary(max_rays: u32) -> Budget {
        Budget {
            depth: 0,
            rays: u64::from(max_rays),
        }
    }

    /// The most rays a secondary ray whose hit is at `depth` spawns, itself included: a full
    /// binary tree down to `max_depth`.
    fn need(max_depth: u32, depth: u32) -> u64 {
        let levels = max_depth.saturating_sub(depth) + 1;
        if levels >= 64 {
            u64::MAX
        } else {
            (1u64 << levels) - 1
        }
    }

    /// Follow the branches a hit has (their weights; None for a branch it does not have):
    /// `follow(branch, budget)` traces one and returns the rays it spent, its own included.
    /// Returns the rays spent in all. The caller stops at `max_depth` before asking.
    ///
    /// Where the budget holds both branches' full trees, each gets its tree. Where it does
    /// not, the stronger branch goes first with its share of the budget in proportion to the
    /// weights, and the weaker gets what the stronger left (a branch that ends early, such as
    /// a ray escaping to the sky, leaves its share to the other).
    pub fn follow(
        self,
        max_depth: u32,
        reflected: Option<f64>,
        refracted: Option<f64>,
        mut follow: impl FnMut(Branch, Budget) -> u64,
    ) -> u64 {
        let need = Self::need(max_depth, self.depth + 1);
        let child = |allowance: u64| {
            (allowance > 0).then(|| Budget {
                depth: self.depth + 1,
                rays: allowance - 1,
            })
        };
        let mut spent = 0;
        let order = match (reflected, refracted) {
            (Some(kr), Some(kt)) if self.rays < need.saturating_mul(2) => {
                let (first, w_first, second, w_second) = if kt > kr {
                    (Branch::Refracted, kt, Branch::Reflected, kr)
                } else {
                    (Branch::Reflected, kr, Branch::Refracted, kt)
                };
                let share = if self.rays <= 1 {
                    self.rays
                } else {
                    let s = self.rays as f64 * w_first / (w_first + w_second);
                    (s.round() as u64).clamp(1, self.rays - 1)
                };
                if let Some(b) = child(share.min(need)) {
                    spent += follow(first, b);
                }
                [Some(second), None]
            }
            (r, t) => [r.map(|_| Branch::Reflected), t.map(|_| Branch::Refracted)],
        };
        for branch in order.into_iter().flatten() {
            if let Some(b) = child((self.rays - spent).min(need)) {
                spent += follow(branch, b);
            }
        }
        spent
    }
}

/// The two ways on from a hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Branch {
    /// The mirror direction.
    Reflected,
    /// Through the surface (Snell's law).
    Refracted,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rays a tree spends when every hit has both branches of the given weights, and every
    /// refracted ray from depth `escape` on leaves the scene (spends no more).
    fn spent(b: Budget, max_depth: u32, kr: f64, kt: f64, escape: u32) -> u64 {
        if b.depth >= max_depth {
            return 0;
        }
        b.follow(max_depth, Some(kr), Some(kt), |branch, c| {
            let ends = branch == Branch::Refracted && c.depth >= escape;
            1 + if ends {
                0
            } else {
                spent(c, max_depth, kr, kt, escape)
            }
        })
    }

    #[test]
    fn a_budget_that_holds_the_full_tree_changes_nothing() {
        // Depth 5: 2 + 4 + 8 + 16 + 32 rays, whatever the weights.
        for (kr, kt) in [(0.5, 0.5), (0.04, 0.96), (1.0, 1.0)] {
            assert_eq!(spent(Budget::primary(62), 5, kr, kt, 99), 62);
            assert_eq!(spent(Budget::primary(1000), 5, kr, kt, 99), 62);
        }
    }

    #[test]
    fn the_budget_bounds_any_depth() {
        for max_rays in [0, 1, 2, 3, 17, 256, 65536] {
            for (kr, kt) in [(0.5, 0.5), (0.04, 0.96), (1.0, 1.0)] {
                let n = spent(Budget::primary(max_rays), 64, kr, kt, 99);
                assert!(n <= u64::from(max_rays), "{n} rays of {max_rays}");
                assert!(n >= u64::from(max_rays.min(64)), "the budget is used: {n}");
            }
        }
    }

    #[test]
    fn what_a_branch_leaves_goes_to_the_other() {
        // Refracted rays escape at once: each reflected ray goes on with all but one ray.
        let n = spent(Budget::primary(10), 64, 0.04, 0.96, 1);
        assert_eq!(n, 10, "the budget is spent down the reflected chain");
    }

    #[test]
    fn the_stronger_branch_goes_first() {
        let mut order = Vec::new();
        let one = Budget { depth: 0, rays: 1 };
        one.follow(8, Some(0.1), Some(0.9), |b, c| {
            order.push((b, c));
            1
        });
        assert_eq!(order, [(Branch::Refracted, Budget { depth: 1, rays: 0 })]);
        order.clear();
        let some = Budget { depth: 0, rays: 10 };
        some.follow(8, Some(0.1), Some(0.9), |b, c| {
            order.push((b, c));
            3
        });
        let got: Vec<(Branch, u64)> = order.iter().map(|(b, c)| (*b, c.rays)).collect();
        assert_eq!(got, [(Branch::Refracted, 8), (Branch::Reflected, 6)]);
        // One branch takes what its tree can use and no more.
        order.clear();
        Budget::primary(1000).follow(2, Some(1.0), None, |b, c| {
            order.push((b, c));
            1
        });
        assert_eq!(order, [(Branch::Reflected, Budget { depth: 1, rays: 2 })]);
    }
}
