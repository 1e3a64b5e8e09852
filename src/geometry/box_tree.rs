//! A bounding-box tree over any items, built with binned SAH: the skeleton of the BVH backend
//! and of the world's culling structure over velocity groups.

use super::Aabb;
use small_stack::SmallStack;

mod small_stack {
    /// A traversal stack on the stack: trees here are at most 64 deep for any realistic input;
    /// deeper pushes spill to the heap rather than fail.
    pub struct SmallStack {
        buf: [(u32, f64); 64],
        len: usize,
        spill: Vec<(u32, f64)>,
    }

    impl Default for SmallStack {
        fn default() -> Self {
            Self::new()
        }
    }

    impl SmallStack {
        pub fn new() -> Self {
            Self {
                buf: [(0, 0.0); 64],
                len: 0,
                spill: Vec::new(),
            }
        }
        #[inline]
        pub fn push(&mut self, v: (u32, f64)) {
            if self.len < self.buf.len() {
                self.buf[self.len] = v;
                self.len += 1;
            } else {
                self.spill.push(v);
            }
        }
        #[inline]
        pub fn pop(&mut self) -> Option<(u32, f64)> {
            if let Some(v) = self.spill.pop() {
                return Some(v);
            }
            if self.len == 0 {
                return None;
            }
            self.len -= 1;
            Some(self.buf[self.len])
        }
    }
}
use glam::DVec3;

const BINS: usize = 16;
const MAX_LEAF: usize = 4;
const TRAVERSAL_COST: f64 = 1.0;
const INTERSECT_COST: f64 = 1.5;

/// Up to this many rays traverse a tree together in [`BoxTree::traverse_packet`].
pub(crate) const PACKET: usize = 16;

/// A node: an interior node has `count == 0` and children at `first` and `first + 1`; a leaf
/// holds `indices[first .. first + count]`.
#[derive(Clone, Copy, Debug)]
pub struct TreeNode {
    pub bounds: Aabb,
    pub first: u32,
    pub count: u32,
}

/// Nodes (root first) and the item order the leaves index into.
pub struct BoxTree {
    pub nodes: Vec<TreeNode>,
    pub indices: Vec<u32>,
}

struct BuildItem {
    node: usize,
    start: usize,
    end: usize,
}

/// An item being sorted into the tree: its box, centroid and index, kept together so the
/// build's passes read memory in order instead of chasing indices.
#[derive(Clone, Copy)]
struct Item {
    bounds: Aabb,
    centroid: DVec3,
    index: u32,
}

impl BoxTree {
    /// This tree's shape over other boxes of the same items (`box_of(item)`, asked once per
    /// item, in leaf order): each node's bounds recomputed (children come after their parents,
    /// so from the last node back). Far cheaper than a build; as tight as one while the boxes
    /// have not moved much.
    pub fn refit_with(&self, mut box_of: impl FnMut(u32) -> Aabb) -> BoxTree {
        let mut nodes = self.nodes.clone();
        if self.indices.is_empty() {
            // The tree of no items: a lone root that is no interior node.
            return BoxTree {
                nodes,
                indices: Vec::new(),
            };
        }
        for n in nodes.iter_mut().filter(|n| n.count > 0) {
            let (first, count) = (n.first as usize, n.count as usize);
            n.bounds = self.indices[first..first + count]
                .iter()
                .fold(Aabb::EMPTY, |b, &k| b.union(&box_of(k)));
        }
        for i in (0..nodes.len()).rev() {
            let n = nodes[i];
            if n.count == 0 {
                let first = n.first as usize;
                nodes[i].bounds = nodes[first].bounds.union(&nodes[first + 1].bounds);
            }
        }
        BoxTree {
            nodes,
            indices: self.indices.clone(),
        }
    }

    /// Build over the boxes of `n` items (binned SAH, leaves of up to 4 items).
    pub fn build(boxes: &[Aabb]) -> BoxTree {
        BoxTree::build_from(boxes.len(), |i| boxes[i])
    }

    /// The same tree as [`build`](Self::build) over the boxes `bounds` gives items `0..n`,
    /// made as they are needed (a mesh's 10 million triangles' boxes are not held twice).
    pub fn build_from(n: usize, bounds: impl Fn(usize) -> Aabb) -> BoxTree {
        let mut items: Vec<Item> = (0..n)
            .map(|i| {
                let b = bounds(i);
                Item {
                    bounds: b,
                    centroid: b.centroid(),
                    index: i as u32,
                }
            })
            .collect();
        let mut nodes = Vec::with_capacity(2 * n.div_ceil(MAX_LEAF).max(1));
        nodes.push(TreeNode {
            bounds: Aabb::EMPTY,
            first: 0,
            count: 0,
        });
        let mut stack = vec![BuildItem {
            node: 0,
            start: 0,
            end: n,
        }];
        while let Some(item) = stack.pop() {
            let part = &mut items[item.start..item.end];
            let (bounds, cbounds) =
                part.iter()
                    .fold((Aabb::EMPTY, Aabb::EMPTY), |(b, mut c), it| {
                        c.grow(it.centroid);
                        (b.union(&it.bounds), c)
                    });
            nodes[item.node].bounds = bounds;
            let count = part.len();
            let split = if count <= 1 {
                None
            } else {
                find_split(part, &bounds, &cbounds)
            };
            let mid = match split {
                Some(m) => Some(m),
                None if count > MAX_LEAF => Some(count / 2), // degenerate centroids: split evenly
                None => None,
            };
            match mid {
                Some(mid) => {
                    if split.is_none() {
                        let e = cbounds.extent();
                        let axis = if e.x >= e.y && e.x >= e.z {
                            0
                        } else if e.y >= e.z {
                            1
                        } else {
                            2
                        };
                        part.select_nth_unstable_by(mid, |a, b| {
                            a.centroid[axis].total_cmp(&b.centroid[axis])
                        });
                    }
                    let left = nodes.len();
                    nodes.push(TreeNode {
                        bounds: Aabb::EMPTY,
                        first: 0,
                        count: 0,
                    });
                    nodes.push(TreeNode {
                        bounds: Aabb::EMPTY,
                        first: 0,
                        count: 0,
                    });
                    nodes[item.node].first = left as u32;
                    nodes[item.node].count = 0;
                    stack.push(BuildItem {
                        node: left + 1,
                        start: item.start + mid,
                        end: item.end,
                    });
                    stack.push(BuildItem {
                        node: left,
                        start: item.start,
                        end: item.start + mid,
                    });
                }
                None => {
                    nodes[item.node].first = item.start as u32;
                    nodes[item.node].count = count as u32;
                }
            }
        }
        BoxTree {
            nodes,
            indices: items.iter().map(|it| it.index).collect(),
        }
    }
}

/// Binned SAH: the split position (count of the left side, after partitioning `items`) or None
/// when a leaf is cheaper.
fn find_split(items: &mut [Item], bounds: &Aabb, cbounds: &Aabb) -> Option<usize> {
    let count = items.len();
    // Fewer bins for few items: the sweep over the bins is the whole cost of a small node.
    let bins = BINS.min(2 * count).max(2);
    let ext = cbounds.extent();
    // The best split so far: cost, axis, bin.
    let mut best: Option<(f64, usize, usize)> = None;
    // Every axis's bins in one pass over the items (a flat axis puts all in bin 0).
    let scale = ext.map(|e| if e > 0.0 { bins as f64 / e } else { 0.0 });
    let mut bins_box = [[Aabb::EMPTY; BINS]; 3];
    let mut bins_n = [[0usize; BINS]; 3];
    for it in items.iter() {
        let b = ((it.centroid - cbounds.min) * scale).as_uvec3();
        for axis in 0..3 {
            let b = (b[axis] as usize).min(bins - 1);
            bins_n[axis][b] += 1;
            bins_box[axis][b] = bins_box[axis][b].union(&it.bounds);
        }
    }
    for axis in 0..3 {
        if ext[axis] <= 0.0 {
            continue;
        }
        let (bin_box, bin_n) = (&bins_box[axis], &bins_n[axis]);
        let mut right_area = [0.0; BINS];
        let mut right_n = [0usize; BINS];
        let (mut acc, mut n) = (Aabb::EMPTY, 0);
        for b in (1..bins).rev() {
            acc = acc.union(&bin_box[b]);
            n += bin_n[b];
            right_area[b] = acc.surface_area();
            right_n[b] = n;
        }
        let (mut acc, mut n) = (Aabb::EMPTY, 0);
        for b in 0..bins - 1 {
            acc = acc.union(&bin_box[b]);
            n += bin_n[b];
            let rn = right_n[b + 1];
            if n == 0 || rn == 0 {
                continue;
            }
            let cost = n as f64 * acc.surface_area() + rn as f64 * right_area[b + 1];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    let (cost, axis, bin) = best?;
    let area = bounds.surface_area().max(f64::MIN_POSITIVE);
    let split_cost = TRAVERSAL_COST + INTERSECT_COST * cost / area;
    if count <= MAX_LEAF && split_cost >= INTERSECT_COST * count as f64 {
        return None;
    }
    let scale = bins as f64 / ext[axis];
    let mut left = 0;
    for k in 0..count {
        let c = items[k].centroid;
        let b = (((c[axis] - cbounds.min[axis]) * scale) as usize).min(bins - 1);
        if b <= bin {
            items.swap(k, left);
            left += 1;
        }
    }
    (left > 0 && left < count).then_some(left)
}

/// A near-first walk over a binary tree laid out as the box tree's nodes are: `node(i)` gives
/// node i's `(first, count)` (interior when count is 0, children at first and first + 1),
/// `entry(i, tmax)` where a ray enters node i (None: it misses), and `visit(item, tmax)` returns
/// the new tmax (the best hit so far); a tmax below tmin stops the walk. Both the box tree and
/// the kinetic group tree walk this way, with different entry tests.
pub(crate) fn walk(
    indices: &[u32],
    node: impl Fn(u32) -> (u32, u32),
    mut entry: impl FnMut(u32, f64) -> Option<f64>,
    tmin: f64,
    tmax: f64,
    mut visit: impl FnMut(u32, f64) -> f64,
) {
    let mut tmax = tmax;
    let mut stack = SmallStack::new();
    if let Some(e) = entry(0, tmax) {
        stack.push((0, e));
    }
    while let Some((i, e)) = stack.pop() {
        if e > tmax {
            continue;
        }
        let (first, count) = node(i);
        if count > 0 {
            for &item in &indices[first as usize..(first + count) as usize] {
                tmax = visit(item, tmax);
                if tmax < tmin {
                    return;
                }
            }
        } else {
            let (l, r) = (first, first + 1);
            match (entry(l, tmax), entry(r, tmax)) {
                (Some(a), Some(b)) if a <= b => {
                    stack.push((r, b));
                    stack.push((l, a));
                }
                (Some(a), Some(b)) => {
                    stack.push((l, a));
                    stack.push((r, b));
                }
                (Some(a), None) => stack.push((l, a)),
                (None, Some(b)) => stack.push((r, b)),
                (None, None) => {}
            }
        }
    }
}

impl BoxTree {
    /// Visit the items whose boxes the ray `o + t d` meets in (tmin, tmax), nearer subtrees
    /// first; `visit(item, tmax)` returns the new tmax, and a tmax below tmin stops the walk.
    pub fn traverse(
        &self,
        o: DVec3,
        d: DVec3,
        tmin: f64,
        tmax: f64,
        visit: impl FnMut(u32, f64) -> f64,
    ) {
        if self.nodes.is_empty() || self.indices.is_empty() {
            return;
        }
        let inv = d.recip();
        let nodes = &self.nodes;
        walk(
            &self.indices,
            |i| (nodes[i as usize].first, nodes[i as usize].count),
            |i, tmax| {
                nodes[i as usize]
                    .bounds
                    .clip(o, inv, tmin, tmax)
                    .map(|x| x.0)
            },
            tmin,
            tmax,
            visit,
        );
    }

    /// Traverse with a packet of up to [`PACKET`] rays from one origin `o` (directions `dirs`,
    /// each searched in `(tmin[i], tmax[i])`): each node is tested with the rays that met its
    /// parent, and descended when any meets it. `visit(item, ray, tmax)` returns the ray's new
    /// tmax; one below its tmin drops the ray.
    pub fn traverse_packet(
        &self,
        o: DVec3,
        dirs: &[DVec3],
        tmin: &[f64],
        tmax: &mut [f64],
        mut visit: impl FnMut(u32, usize, f64) -> f64,
    ) {
        let nodes = &self.nodes;
        if nodes.is_empty() || self.indices.is_empty() {
            return;
        }
        let n = dirs.len().min(PACKET);
        let mut inv = [DVec3::ZERO; PACKET];
        for (i, d) in dirs.iter().take(n).enumerate() {
            inv[i] = d.recip();
        }
        let hits_node = |b: &Aabb, tmax: &[f64], parent: u32| -> u32 {
            let (mut mask, mut rest) = (0u32, parent);
            while rest != 0 {
                let i = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                mask |= u32::from(b.clip(o, inv[i], tmin[i], tmax[i]).is_some()) << i;
            }
            mask
        };
        let mut stack = [(0u32, 0u32); 128];
        stack[0] = (0, (1u32 << n) - 1); // n ≤ PACKET < 32
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let (index, parent) = stack[sp];
            let node = nodes[index as usize];
            let mask = hits_node(&node.bounds, tmax, parent);
            if mask == 0 {
                continue;
            }
            if node.count > 0 {
                let mut live = mask;
                for &item in &self.indices[node.first as usize..(node.first + node.count) as usize]
                {
                    let mut rest = live;
                    while rest != 0 {
                        let i = rest.trailing_zeros() as usize;
                        rest &= rest - 1;
                        tmax[i] = visit(item, i, tmax[i]);
                        if tmax[i] < tmin[i] {
                            live &= !(1 << i);
                        }
                    }
                }
            } else if sp + 2 <= stack.len() {
                stack[sp] = (node.first + 1, mask);
                stack[sp + 1] = (node.first, mask);
                sp += 2;
            } else {
                // Deeper than any tree built here; fall back to one ray at a time.
                let mut rest = mask;
                while rest != 0 {
                    let i = rest.trailing_zeros() as usize;
                    rest &= rest - 1;
                    let mut t = tmax[i];
                    self.traverse(o, dirs[i], tmin[i], t, |item, tm| {
                        t = visit(item, i, tm);
                        t
                    });
                    tmax[i] = t;
                }
            }
        }
    }
}
