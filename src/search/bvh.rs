//! A bounding-volume hierarchy over axis-aligned boxes, for the broad phase of the
//! contact search.
//!
//! Entry points: [`Aabb`] (a box, with [`Aabb::from_points`], [`Aabb::inflate`],
//! [`Aabb::intersects`], [`Aabb::union`]), [`Bvh::build`], [`Bvh::refit`],
//! [`Bvh::query`], [`Bvh::query_with_box`] (hands the candidate's box to the narrow
//! phase), [`Bvh::query_with_hint`] (for coherent streams of queries, starts at the
//! previous query's leaf), [`Bvh::query_point_within`] and [`Bvh::query_by`] (any
//! monotone box predicate).
//!
//! Construction: a top-down median split on the longest axis of the item centroids'
//! bounds, down to leaves of at most [`LEAF_SIZE`] items. Splitting at the median of the
//! *count* keeps the tree balanced whatever the geometry (depth ≤ ⌈log₂ n⌉), so the
//! build is O(n log n) (a linear-time selection per level) and the query stack has a
//! fixed size. Ties between equal centroids are broken by item index, so the same input
//! always gives the same tree. The median split also fixes how many nodes a subtree has
//! from its item count alone, so the two halves of a large split are built on the
//! thread pool side by side, each into its own range of the node array: the tree is
//! the one a single pass in pre-order makes, on any number of threads.
//!
//! Layout: one flat node array in depth-first pre-order (the left child of node `i` is
//! `i + 1`, the right child is stored), plus the item permutation and a copy of the item
//! boxes in leaf order, so that a query reads memory mostly forwards and never touches the
//! caller's array. [`Bvh::item_order`] exposes the leaf order, a spatially coherent order
//! in which to issue many queries for cache locality.
//!
//! Boxes are closed: boxes that only touch intersect. A box with `min > max` on some axis
//! is empty and intersects nothing. Queries report items in a deterministic order (the
//! leaf order of the tree; for [`Bvh::query_with_hint`], an order fixed by the hint).
//! The parent links add 4 bytes per node; a node is 56 bytes.

use crate::vec3::V3;

/// Maximum number of items in a leaf.
pub const LEAF_SIZE: usize = 4;

/// An axis-aligned box `[min, max]` (closed). Empty when `min[k] > max[k]` on some axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

impl Aabb {
    /// The empty box: the identity of [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
    };

    /// The box of a single point.
    pub fn from_point(p: [f64; 3]) -> Aabb {
        Aabb { min: p, max: p }
    }

    /// The smallest box holding all `points` ([`Aabb::EMPTY`] for none).
    pub fn from_points(points: &[[f64; 3]]) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in points {
            b = b.union(&Aabb::from_point(*p));
        }
        b
    }

    /// The box grown by `margin` on every side (shrunk for a negative margin).
    pub fn inflate(&self, margin: f64) -> Aabb {
        Aabb {
            min: [
                self.min[0] - margin,
                self.min[1] - margin,
                self.min[2] - margin,
            ],
            max: [
                self.max[0] + margin,
                self.max[1] + margin,
                self.max[2] + margin,
            ],
        }
    }

    /// Whether the two closed boxes share at least one point.
    #[inline]
    pub fn intersects(&self, other: &Aabb) -> bool {
        // Non-short-circuit `&`: one branch for the caller instead of six
        // hard-to-predict ones in the tree traversal.
        (self.min[0] <= other.max[0])
            & (other.min[0] <= self.max[0])
            & (self.min[1] <= other.max[1])
            & (other.min[1] <= self.max[1])
            & (self.min[2] <= other.max[2])
            & (other.min[2] <= self.max[2])
    }

    /// The smallest box holding both.
    #[inline]
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: [
                self.min[0].min(other.min[0]),
                self.min[1].min(other.min[1]),
                self.min[2].min(other.min[2]),
            ],
            max: [
                self.max[0].max(other.max[0]),
                self.max[1].max(other.max[1]),
                self.max[2].max(other.max[2]),
            ],
        }
    }

    /// Whether the box holds no point.
    pub fn is_empty(&self) -> bool {
        (0..3).any(|k| self.min[k] > self.max[k] || self.min[k].is_nan() || self.max[k].is_nan())
    }

    /// The centre `(min + max) / 2`.
    pub fn center(&self) -> [f64; 3] {
        [
            0.5 * (self.min[0] + self.max[0]),
            0.5 * (self.min[1] + self.max[1]),
            0.5 * (self.min[2] + self.max[2]),
        ]
    }

    /// Squared Euclidean distance from `p` to the box (0 inside).
    #[inline]
    pub fn distance2_to_point(&self, p: [f64; 3]) -> f64 {
        let mut d2 = 0.0;
        for ((lo, hi), x) in self.min.iter().zip(&self.max).zip(&p) {
            let d = (lo - x).max(x - hi).max(0.0);
            d2 += d * d;
        }
        d2
    }
}

/// Where [`Bvh::query_with_hint`] starts: the leaf of the previous query's first hit.
/// The default starts at the root. A hint from another tree is harmless (only slower).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct QueryHint {
    node: u32,
}

/// One node of the flat tree. A leaf holds items `start .. start + count` of the
/// permutation; an interior node (`count == 0`) has its left child right after it and its
/// right child at `start`.
#[derive(Debug, Clone, Copy)]
struct Node {
    bounds: Aabb,
    start: u32,
    count: u32,
}

/// A bounding-volume hierarchy over a fixed list of boxes (items `0 .. n`).
#[derive(Debug, Clone)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Parent of each node (the root's entry is unused).
    parent: Vec<u32>,
    /// Item index at each leaf slot.
    order: Vec<u32>,
    /// Item boxes in leaf-slot order.
    boxes: Vec<Aabb>,
}

/// Depth bound of the stack in the queries: the median split gives depth ≤ ⌈log₂ n⌉ < 64.
const STACK: usize = 64;

impl Bvh {
    /// Builds the tree over `items` (item `i` is `items[i]`).
    ///
    /// # Panics
    /// If there are `u32::MAX` items or more (the node layout stores 32-bit indices).
    pub fn build(items: &[Aabb]) -> Bvh {
        use rayon::prelude::*;
        let n = items.len();
        assert!(
            n < u32::MAX as usize,
            "Bvh::build: {n} items exceed the 32-bit index range"
        );
        let centers: Vec<V3> = items.par_iter().map(Aabb::center).collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = vec![
            Node {
                bounds: Aabb::EMPTY,
                start: 0,
                count: 0,
            };
            if n == 0 { 0 } else { subtree_nodes(n) }
        ];
        if n > 0 {
            let tree = Tree {
                centers: &centers,
                items,
            };
            tree.build_split(&mut order, 0, &mut nodes, 0);
        }
        let boxes = order.par_iter().map(|&i| items[i as usize]).collect();
        let mut parent = vec![0u32; nodes.len()];
        for (k, node) in nodes.iter().enumerate() {
            if node.count == 0 {
                parent[k + 1] = k as u32;
                parent[node.start as usize] = k as u32;
            }
        }
        Bvh {
            nodes,
            parent,
            order,
            boxes,
        }
    }

    /// Number of items.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    /// Whether the tree has no items.
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// The items in leaf order: a spatially coherent permutation of `0 .. n`.
    pub fn item_order(&self) -> impl ExactSizeIterator<Item = usize> + '_ {
        self.order.iter().map(|&i| i as usize)
    }

    /// The box of the whole tree ([`Aabb::EMPTY`] when empty).
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds)
    }

    /// Recomputes every node box bottom-up for moved `items`, keeping the topology. The
    /// tree stays correct (queries exact) whatever the motion, but it may lose quality
    /// after large motions; rebuild then.
    ///
    /// # Panics
    /// If `items.len()` differs from the number the tree was built with.
    pub fn refit(&mut self, items: &[Aabb]) {
        assert_eq!(
            items.len(),
            self.order.len(),
            "Bvh::refit: item count differs from the built tree"
        );
        for (slot, &i) in self.boxes.iter_mut().zip(&self.order) {
            *slot = items[i as usize];
        }
        self.fit_bounds();
    }

    /// Node boxes bottom-up from the leaf boxes.
    fn fit_bounds(&mut self) {
        // Pre-order: children have larger indices than their parent.
        for k in (0..self.nodes.len()).rev() {
            let node = self.nodes[k];
            let bounds = if node.count > 0 {
                let s = node.start as usize;
                self.boxes[s..s + node.count as usize]
                    .iter()
                    .fold(Aabb::EMPTY, |b, x| b.union(x))
            } else {
                self.nodes[k + 1]
                    .bounds
                    .union(&self.nodes[node.start as usize].bounds)
            };
            self.nodes[k].bounds = bounds;
        }
    }

    /// Calls `visit(i)` for every item `i` whose box intersects `query`, in leaf order.
    /// Allocates nothing.
    pub fn query(&self, query: &Aabb, mut visit: impl FnMut(usize)) {
        self.query_with_box(query, |i, _| visit(i));
    }

    /// Like [`Bvh::query`], handing the item's box to `visit` too (read from the tree's
    /// own copy, already in cache), so a narrow phase can skip candidates whose box is
    /// farther than the best found so far.
    pub fn query_with_box(&self, query: &Aabb, mut visit: impl FnMut(usize, &Aabb)) {
        self.traverse_from(
            0,
            |b| b.intersects(query),
            |_, boxes, items| {
                for (b, &i) in boxes.iter().zip(items) {
                    if b.intersects(query) {
                        visit(i as usize, b);
                    }
                }
            },
        );
    }

    /// Calls `visit(i, b)` for every item `i` whose box `b` the predicate `accept` takes,
    /// descending only into the nodes whose box it takes, in leaf order. `accept` must be
    /// monotone: a box it rejects holds no box it takes (as "intersects a query box" or
    /// "comes within a distance of a point" are), so a rejected node hides nothing. This
    /// lets a caller that knows more than the boxes prune by it — the contact search
    /// shrinks every box by its margin again to test the faces' own boxes against its
    /// reach. Allocates nothing.
    pub fn query_by(&self, accept: impl Fn(&Aabb) -> bool, mut visit: impl FnMut(usize, &Aabb)) {
        self.traverse_from(0, &accept, |_, boxes, items| {
            for (b, &i) in boxes.iter().zip(items) {
                if accept(b) {
                    visit(i as usize, b);
                }
            }
        });
    }

    /// Like [`Bvh::query_with_box`], for a stream of nearby queries: the search starts
    /// at the leaf where the previous query found its first item (kept in `hint`) and
    /// climbs to the root, testing at each level the sibling of the subtree already
    /// searched. Every item is still found (the siblings along the path to the root
    /// cover the whole tree), whatever the hint; a good hint only makes the tests cheap,
    /// since for a small query most siblings miss, which the branch predictor learns,
    /// where a descent from the root takes a coin-flip branch per level. Issue queries
    /// in a spatially coherent order (e.g. Morton order of the points) to profit.
    ///
    /// The report order depends on the hint (it is deterministic for a deterministic
    /// sequence of queries); the set reported equals that of [`Bvh::query`].
    pub fn query_with_hint(
        &self,
        hint: &mut QueryHint,
        query: &Aabb,
        visit: impl FnMut(usize, &Aabb),
    ) {
        self.query_by_with_hint(hint, |b| b.intersects(query), visit);
    }

    /// [`Bvh::query_by`] started at the hint's leaf as [`Bvh::query_with_hint`] does:
    /// the same set of items for the same monotone `accept`, in an order that depends on
    /// the hint.
    pub fn query_by_with_hint(
        &self,
        hint: &mut QueryHint,
        accept: impl Fn(&Aabb) -> bool,
        mut visit: impl FnMut(usize, &Aabb),
    ) {
        let start = hint.node as usize;
        let start = if start < self.nodes.len() { start } else { 0 };
        let mut first_hit: Option<usize> = None;
        let mut leaf = |k: usize, boxes: &[Aabb], items: &[u32]| {
            for (b, &i) in boxes.iter().zip(items) {
                if accept(b) {
                    first_hit.get_or_insert(k);
                    visit(i as usize, b);
                }
            }
        };
        self.traverse_from(start, &accept, &mut leaf);
        let mut c = start;
        while c != 0 {
            let p = self.parent[c] as usize;
            let sibling = if c == p + 1 {
                self.nodes[p].start as usize
            } else {
                p + 1
            };
            // Test here first: most siblings miss, and a miss then costs one box test.
            if accept(&self.nodes[sibling].bounds) {
                self.traverse_from(sibling, &accept, &mut leaf);
            }
            c = p;
        }
        if let Some(k) = first_hit {
            hint.node = k as u32;
        }
    }

    /// Calls `visit(i)` for every item `i` whose box lies within distance `radius` of `p`
    /// (closed: distance ≤ radius), in leaf order. Allocates nothing.
    pub fn query_point_within(&self, p: [f64; 3], radius: f64, mut visit: impl FnMut(usize)) {
        let r2 = radius * radius;
        if radius.is_nan() || radius < 0.0 {
            return;
        }
        self.traverse_from(
            0,
            |b| b.distance2_to_point(p) <= r2,
            |_, boxes, items| {
                for (b, &i) in boxes.iter().zip(items) {
                    if b.distance2_to_point(p) <= r2 {
                        visit(i as usize);
                    }
                }
            },
        );
    }

    /// Depth-first traversal of the subtree at node `start` (left before right),
    /// descending into nodes accepted by `enter` and handing the node index, boxes and
    /// items of every accepted leaf to `leaf`. Does nothing for an empty tree.
    #[inline(always)]
    fn traverse_from(
        &self,
        start: usize,
        enter: impl Fn(&Aabb) -> bool,
        mut leaf: impl FnMut(usize, &[Aabb], &[u32]),
    ) {
        if start >= self.nodes.len() {
            return;
        }
        let mut stack = [0u32; STACK];
        let mut top = 0usize;
        let mut k = start;
        loop {
            let node = &self.nodes[k];
            let mut next = None;
            if enter(&node.bounds) {
                if node.count > 0 {
                    let s = node.start as usize;
                    let e = s + node.count as usize;
                    leaf(k, &self.boxes[s..e], &self.order[s..e]);
                } else {
                    stack[top] = node.start;
                    top += 1;
                    next = Some(k + 1);
                }
            }
            match next {
                Some(c) => k = c,
                None if top > 0 => {
                    top -= 1;
                    k = stack[top] as usize;
                }
                None => return,
            }
        }
    }
}

/// Items from which a subtree is built on its own thread's share: below it, the two
/// halves of a split are built one after the other.
const PARALLEL_ITEMS: usize = 1 << 14;

/// The number of nodes of the subtree over `n ≥ 1` items: the median split makes it a
/// function of `n` alone (`⌊n/2⌋` items left, the rest right, leaves of at most
/// [`LEAF_SIZE`]), which lets the two halves of a split be built side by side into
/// their own ranges of the node array. The sizes at one depth differ by at most one, so
/// the recursion on the pair `(f(m), f(m + 1))` visits one `m` per depth.
fn subtree_nodes(n: usize) -> usize {
    /// `(f(m), f(m + 1))`.
    fn pair(m: usize) -> (usize, usize) {
        if m < LEAF_SIZE {
            return (1, 1);
        }
        if m <= LEAF_SIZE {
            // f(m) = 1; m + 1 splits into ⌊(m+1)/2⌋ and ⌈(m+1)/2⌉, both leaves.
            return (1, 3);
        }
        // f(k) = 1 + f(⌊k/2⌋) + f(⌈k/2⌉) for k = m and m + 1; the four halves lie in
        // {h, h + 1} with h = ⌊m/2⌋.
        let h = m / 2;
        let (fh, fh1) = pair(h);
        let f = |k: usize| {
            let (lo, hi) = (k / 2, k - k / 2);
            let g = |j: usize| if j == h { fh } else { fh1 };
            1 + g(lo) + g(hi)
        };
        (f(m), f(m + 1))
    }
    pair(n).0
}

/// What every subtree of one build reads: the items' centroids and boxes.
struct Tree<'a> {
    centers: &'a [V3],
    items: &'a [Aabb],
}

impl Tree<'_> {
    /// Builds the subtree over `order[..]` (which starts at leaf slot `offset`) into
    /// `nodes`, which has exactly [`subtree_nodes`] of them and holds node `base` of the
    /// whole tree first, in pre-order, boxes included; returns the subtree's box. The
    /// same tree as one pass in pre-order: each half's nodes land where that pass would
    /// have pushed them.
    fn build_split(
        &self,
        order: &mut [u32],
        offset: usize,
        nodes: &mut [Node],
        base: usize,
    ) -> Aabb {
        let n = order.len();
        debug_assert_eq!(nodes.len(), subtree_nodes(n));
        if n <= LEAF_SIZE {
            nodes[0] = Node {
                bounds: self.leaf_bounds(order),
                start: offset as u32,
                count: n as u32,
            };
            return nodes[0].bounds;
        }
        let mid = self.split(order);
        let (left, right) = order.split_at_mut(mid);
        let (root, rest) = nodes.split_first_mut().expect("a subtree has a node");
        let (left_nodes, right_nodes) = rest.split_at_mut(subtree_nodes(mid));
        let right_index = base + 1 + left_nodes.len();
        let (left_bounds, right_bounds) = if n >= PARALLEL_ITEMS {
            rayon::join(
                || self.build_split(left, offset, left_nodes, base + 1),
                || self.build_split(right, offset + mid, right_nodes, right_index),
            )
        } else {
            (
                self.build_split(left, offset, left_nodes, base + 1),
                self.build_split(right, offset + mid, right_nodes, right_index),
            )
        };
        *root = Node {
            bounds: left_bounds.union(&right_bounds),
            start: right_index as u32,
            count: 0,
        };
        root.bounds
    }

    /// A leaf's box: the union of its items' boxes in leaf order, as
    /// [`Bvh::fit_bounds`] makes it.
    fn leaf_bounds(&self, order: &[u32]) -> Aabb {
        order
            .iter()
            .fold(Aabb::EMPTY, |b, &i| b.union(&self.items[i as usize]))
    }

    /// Splits `order` at its median along the longest axis of its centroids' bounds
    /// (NaN extents never win) and returns the median's place, `n / 2`.
    fn split(&self, order: &mut [u32]) -> usize {
        let centers = self.centers;
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for &i in order.iter() {
            let c = centers[i as usize];
            for k in 0..3 {
                lo[k] = lo[k].min(c[k]);
                hi[k] = hi[k].max(c[k]);
            }
        }
        let mut axis = 0;
        for k in 1..3 {
            if hi[k] - lo[k] > hi[axis] - lo[axis] {
                axis = k;
            }
        }
        let mid = order.len() / 2;
        // Total order (coordinate, then index): the split sets do not depend on the
        // selection algorithm, so equal inputs give equal trees.
        order.select_nth_unstable_by(mid, |&a, &b| {
            centers[a as usize][axis]
                .total_cmp(&centers[b as usize][axis])
                .then(a.cmp(&b))
        });
        mid
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box(x: f64, y: f64, z: f64) -> Aabb {
        Aabb {
            min: [x, y, z],
            max: [x + 1.0, y + 1.0, z + 1.0],
        }
    }

    fn collect(bvh: &Bvh, q: &Aabb) -> Vec<usize> {
        let mut v = Vec::new();
        bvh.query(q, |i| v.push(i));
        v
    }

    #[test]
    fn empty_and_single() {
        let bvh = Bvh::build(&[]);
        assert!(bvh.is_empty());
        assert!(collect(&bvh, &unit_box(0.0, 0.0, 0.0)).is_empty());
        let bvh = Bvh::build(&[unit_box(0.0, 0.0, 0.0)]);
        assert_eq!(collect(&bvh, &unit_box(0.5, 0.5, 0.5)), vec![0]);
        assert!(collect(&bvh, &unit_box(2.0, 0.0, 0.0)).is_empty());
        // Touching boxes intersect (closed boxes).
        assert_eq!(collect(&bvh, &unit_box(1.0, 0.0, 0.0)), vec![0]);
    }

    /// The node count of a subtree by its definition, for the closed recursion.
    fn nodes_by_definition(n: usize) -> usize {
        if n <= LEAF_SIZE {
            1
        } else {
            1 + nodes_by_definition(n / 2) + nodes_by_definition(n - n / 2)
        }
    }

    #[test]
    fn subtree_node_counts_follow_the_median_split() {
        for n in (1..3000).chain([65_535, 65_536, 65_537, 100_003]) {
            assert_eq!(subtree_nodes(n), nodes_by_definition(n), "n = {n}");
        }
    }

    /// The tree built with its halves on two threads (subtrees of 2¹⁴ items and more)
    /// against one thread and against one pass in pre-order without the count formula,
    /// node for node, boxes and permutation included. The items are jittered boxes with
    /// repeated centroids, so ties between equal coordinates are exercised.
    #[test]
    fn parallel_build_is_the_serial_tree() {
        let n = 70_001;
        let items: Vec<Aabb> = (0..n)
            .map(|i| {
                let (x, y) = ((i % 263) as f64, ((i / 263) % 97) as f64);
                let z = ((i * 7919) % 5) as f64 * 0.25;
                let w = 0.5 + ((i * 31) % 7) as f64 * 0.1;
                Aabb {
                    min: [x, y, z],
                    max: [x + w, y + 1.0, z + w],
                }
            })
            .collect();
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| Bvh::build(&items))
        };
        let (one, two) = (on(1), on(2));
        // One pass in pre-order, pushing nodes as they are made, then boxes bottom-up.
        fn push(tree: &Tree, order: &mut [u32], offset: usize, nodes: &mut Vec<Node>) {
            let me = nodes.len();
            nodes.push(Node {
                bounds: Aabb::EMPTY,
                start: offset as u32,
                count: order.len() as u32,
            });
            if order.len() > LEAF_SIZE {
                let mid = tree.split(order);
                let (left, right) = order.split_at_mut(mid);
                push(tree, left, offset, nodes);
                let right_index = nodes.len();
                push(tree, right, offset + mid, nodes);
                nodes[me].start = right_index as u32;
                nodes[me].count = 0;
            }
        }
        let centers: Vec<V3> = items.iter().map(Aabb::center).collect();
        let tree = Tree {
            centers: &centers,
            items: &items,
        };
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::new();
        push(&tree, &mut order, 0, &mut nodes);
        // (Parents are checked below against their definition.)
        let mut serial = Bvh {
            nodes,
            parent: Vec::new(),
            boxes: order.iter().map(|&i| items[i as usize]).collect(),
            order,
        };
        serial.fit_bounds();
        assert_eq!(two.parent, one.parent);
        for (k, node) in two.nodes.iter().enumerate().filter(|(_, n)| n.count == 0) {
            // An internal node is the parent of the node after it and of its right child.
            assert_eq!(two.parent[k + 1] as usize, k);
            assert_eq!(two.parent[node.start as usize] as usize, k);
        }
        for other in [&one, &serial] {
            assert_eq!(two.order, other.order);
            assert_eq!(two.boxes, other.boxes);
            assert_eq!(two.nodes.len(), other.nodes.len());
            for (a, b) in two.nodes.iter().zip(&other.nodes) {
                assert_eq!((a.bounds, a.start, a.count), (b.bounds, b.start, b.count));
            }
        }
    }

    #[test]
    fn duplicates_and_flat_boxes() {
        // 100 identical flat boxes: all centroids equal, the split must still terminate
        // with small leaves and report every item once.
        let flat = Aabb {
            min: [0.0, 0.0, 0.0],
            max: [1.0, 1.0, 0.0],
        };
        let items = vec![flat; 100];
        let bvh = Bvh::build(&items);
        let mut got = collect(&bvh, &Aabb::from_point([0.5, 0.5, 0.0]));
        got.sort_unstable();
        assert_eq!(got, (0..100).collect::<Vec<_>>());
        assert!(collect(&bvh, &Aabb::from_point([0.5, 0.5, 1e-12])).is_empty());
    }

    #[test]
    fn grid_query_and_refit() {
        let mut items = Vec::new();
        for i in 0..10 {
            for j in 0..10 {
                items.push(unit_box(2.0 * i as f64, 2.0 * j as f64, 0.0));
            }
        }
        let mut bvh = Bvh::build(&items);
        // A point inside box (3, 4) only.
        let q = Aabb::from_point([6.5, 8.5, 0.5]);
        assert_eq!(collect(&bvh, &q), vec![34]);
        // Move every box by +1 in x; refit; the point now sits in the gap between boxes.
        for b in &mut items {
            b.min[0] += 1.0;
            b.max[0] += 1.0;
        }
        bvh.refit(&items);
        assert!(collect(&bvh, &q).is_empty());
        assert_eq!(collect(&bvh, &Aabb::from_point([7.5, 8.5, 0.5])), vec![34]);
        let mut within = Vec::new();
        bvh.query_point_within([6.5, 8.5, 0.5], 0.5, |i| within.push(i));
        within.sort_unstable();
        assert_eq!(within, vec![24, 34]);
    }

    #[test]
    fn hints_from_anywhere_give_the_same_set() {
        let big: Vec<Aabb> = (0..500)
            .map(|i| unit_box((i % 25) as f64 * 1.5, (i / 25) as f64 * 1.5, 0.0))
            .collect();
        let small: Vec<Aabb> = big[..40].to_vec();
        let (tb, ts) = (Bvh::build(&big), Bvh::build(&small));
        // A hint left at a deep leaf of the big tree is out of range for the small one.
        let mut hint = QueryHint::default();
        let far = Aabb::from_point([30.0, 28.0, 0.5]);
        tb.query_with_hint(&mut hint, &far, |_, _| {});
        assert_ne!(hint, QueryHint::default());
        for q in [unit_box(0.2, 0.2, 0.0), unit_box(3.0, 1.0, -0.5), far] {
            for tree in [&tb, &ts] {
                let mut got = Vec::new();
                let mut h = hint;
                tree.query_with_hint(&mut h, &q, |i, _| got.push(i));
                got.sort_unstable();
                let mut want = collect(tree, &q);
                want.sort_unstable();
                assert_eq!(got, want);
            }
        }
    }

    /// A predicate that prunes harder than box intersection (here: a box whose centre
    /// is within 2 of a point, monotone as required) finds what testing every item does.
    #[test]
    fn query_by_equals_testing_every_item() {
        let items: Vec<Aabb> = (0..300)
            .map(|i| unit_box(((i * 37) % 41) as f64 * 0.7, ((i * 11) % 13) as f64, 0.0))
            .collect();
        let bvh = Bvh::build(&items);
        let p = [9.0, 5.5, 0.5];
        // Within 2 of p once shrunk by 0.5 on every side (monotone: a box inside a box
        // that fails fails too).
        let accept = |b: &Aabb| b.inflate(-0.5).distance2_to_point(p) <= 4.0;
        let mut got = Vec::new();
        bvh.query_by(accept, |i, b| {
            assert_eq!(*b, items[i]);
            got.push(i);
        });
        got.sort_unstable();
        let want: Vec<usize> = (0..items.len()).filter(|&i| accept(&items[i])).collect();
        assert!(!want.is_empty() && want.len() < items.len());
        assert_eq!(got, want);
        // The same from a hint left by each of a stream of other queries.
        let mut hint = QueryHint::default();
        for k in 0..40 {
            let q = [(k as f64) * 0.7, (k % 13) as f64, 0.5];
            bvh.query_by_with_hint(&mut hint, |b| b.distance2_to_point(q) <= 1.0, |_, _| {});
            let mut from_hint = Vec::new();
            let mut h = hint;
            bvh.query_by_with_hint(&mut h, accept, |i, _| from_hint.push(i));
            from_hint.sort_unstable();
            assert_eq!(from_hint, want, "from the hint of query {k}");
        }
    }

    #[test]
    fn same_input_same_tree() {
        let items: Vec<Aabb> = (0..257)
            .map(|i| unit_box(((i * 37) % 101) as f64, ((i * 53) % 7) as f64, 0.0))
            .collect();
        let a = Bvh::build(&items);
        let b = Bvh::build(&items);
        assert_eq!(a.order, b.order);
        let q = unit_box(10.0, 2.0, 0.0).inflate(5.0);
        assert_eq!(collect(&a, &q), collect(&b, &q));
    }
}
