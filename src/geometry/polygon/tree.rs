//! A 2-d tree over a set of points of the plane, built once, for the question "which
//! points may lie in this triangle?".
//!
//! The points are split at the median of the wider extent of their bounding box, down
//! to leaves of a few points; each node keeps its points' bounding box, and the nodes
//! are stored as an implicit binary tree (the children of node `i` are `2i + 1` and
//! `2i + 2`), so building costs `O(k log k)` and no pointer. A query descends into the
//! nodes whose box meets the triangle's bounding box and does not lie wholly outside
//! one of its edges, so it costs about the logarithm of the point count plus the nodes
//! along the triangle, however the points are spread (along a curve, as a polygon's
//! vertices are) and however long and thin the triangle is.
//!
//! Pruning is conservative: a node is skipped only when it is outside by a margin far
//! above the rounding error of the test the caller makes on each point, so the points
//! the caller would accept are never skipped.

/// Points per leaf at most.
const LEAF: usize = 8;

/// The deepest a tree of up to `usize::MAX` points goes, with room to spare.
const MAX_DEPTH: usize = 64;

/// Relative margin of the pruning tests.
const MARGIN: f64 = 1e-9;

/// Points in a 2-d tree.
#[derive(Debug, Default)]
pub(super) struct Tree {
    /// The points (indices into the coordinates), each node's contiguous.
    items: Vec<usize>,
    /// Each node's bounding box: `[xmin, ymin, xmax, ymax]`.
    boxes: Vec<[f64; 4]>,
}

impl Tree {
    /// Build over `points` (indices into `xy`), replacing what the tree held.
    pub fn build(&mut self, xy: &[[f64; 2]], points: &[usize]) {
        self.items.clear();
        self.items.extend_from_slice(points);
        self.boxes.clear();
        self.boxes.resize(node_count(points.len()), [0.0; 4]);
        if !points.is_empty() {
            self.split(xy, 0, 0, points.len());
        }
    }

    /// The points the tree holds.
    pub fn items(&self) -> &[usize] {
        &self.items
    }

    /// Compute node `node`'s box over `items[lo..hi]` and split it, recursively.
    fn split(&mut self, xy: &[[f64; 2]], node: usize, lo: usize, hi: usize) {
        let b = bounds(xy, &self.items[lo..hi]);
        self.boxes[node] = b;
        if hi - lo <= LEAF {
            return;
        }
        let axis = usize::from(b[3] - b[1] > b[2] - b[0]);
        let mid = (lo + hi) / 2;
        self.items[lo..hi]
            .select_nth_unstable_by(mid - lo, |&p, &q| xy[p][axis].total_cmp(&xy[q][axis]));
        self.split(xy, 2 * node + 1, lo, mid);
        self.split(xy, 2 * node + 2, mid, hi);
    }

    /// Call `hit` on the points of every leaf that may meet the triangle `t` (turning
    /// counterclockwise once multiplied by `sign`) until it returns true; the point it
    /// did for. Every node and point looked at adds one to `work`.
    pub fn find(
        &self,
        t: [[f64; 2]; 3],
        sign: f64,
        work: &mut u64,
        mut hit: impl FnMut(usize) -> bool,
    ) -> Option<usize> {
        if self.items.is_empty() {
            return None;
        }
        let reach = padded_bounds(t);
        let mut stack = [(0usize, 0usize, 0usize); MAX_DEPTH];
        stack[0] = (0, 0, self.items.len());
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (node, lo, hi) = stack[top];
            *work += 1;
            let b = self.boxes[node];
            if !overlap(b, reach) || outside_an_edge(b, t, sign) {
                continue;
            }
            if hi - lo <= LEAF {
                for &p in &self.items[lo..hi] {
                    *work += 1;
                    if hit(p) {
                        return Some(p);
                    }
                }
                continue;
            }
            let mid = (lo + hi) / 2;
            stack[top] = (2 * node + 1, lo, mid);
            stack[top + 1] = (2 * node + 2, mid, hi);
            top += 2;
        }
        None
    }
}

/// Nodes of the implicit tree over `k` points: a complete tree as deep as the longest
/// path of halvings (the larger half each time) down to a leaf.
fn node_count(k: usize) -> usize {
    let mut size = k;
    let mut depth = 0;
    while size > LEAF {
        size = size.div_ceil(2);
        depth += 1;
    }
    (1 << (depth + 1)) - 1
}

/// The bounding box `[xmin, ymin, xmax, ymax]` of `points`.
fn bounds(xy: &[[f64; 2]], points: &[usize]) -> [f64; 4] {
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for &p in points {
        b[0] = b[0].min(xy[p][0]);
        b[1] = b[1].min(xy[p][1]);
        b[2] = b[2].max(xy[p][0]);
        b[3] = b[3].max(xy[p][1]);
    }
    b
}

/// The triangle's bounding box, widened by [`MARGIN`] of its size.
fn padded_bounds(t: [[f64; 2]; 3]) -> [f64; 4] {
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for p in t {
        b[0] = b[0].min(p[0]);
        b[1] = b[1].min(p[1]);
        b[2] = b[2].max(p[0]);
        b[3] = b[3].max(p[1]);
    }
    let pad = MARGIN * ((b[2] - b[0]) + (b[3] - b[1]) + b[0].abs().max(b[2].abs()));
    [b[0] - pad, b[1] - pad, b[2] + pad, b[3] + pad]
}

/// Whether two boxes meet (false for NaN).
fn overlap(a: [f64; 4], b: [f64; 4]) -> bool {
    a[0] <= b[2] && b[0] <= a[2] && a[1] <= b[3] && b[1] <= a[3]
}

/// Whether the box lies wholly, and by a margin, outside one of the triangle's edges.
fn outside_an_edge(b: [f64; 4], t: [[f64; 2]; 3], sign: f64) -> bool {
    let corners = [[b[0], b[1]], [b[2], b[1]], [b[0], b[3]], [b[2], b[3]]];
    (0..3).any(|k| {
        let (p, q) = (t[k], t[(k + 1) % 3]);
        let e = [q[0] - p[0], q[1] - p[1]];
        let len = e[0].abs() + e[1].abs();
        corners.iter().all(|c| {
            let d = [c[0] - p[0], c[1] - p[1]];
            let side = sign * (e[0] * d[1] - e[1] * d[0]);
            side < -MARGIN * len * (d[0].abs() + d[1].abs())
        })
    })
}
