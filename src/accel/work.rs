//! Work counters (after pbrt-v4's statistics counters): deterministic counts of what ray queries
//! cost, which do not move between runs when time does. Every structure's CPU walk counts the
//! nodes it visits and the primitives it tests into a per-thread tally; the CPU backend collects
//! each pixel's tally where the pixel is computed ([`counted`]), so counts are exact whatever the
//! thread count or whatever else runs in the process.
//!
//! The GPU counts its own walks (`work_nodes`, `work_prims`), which match the CPU's only where
//! they walk alike. The kd-tree walks alike but for its planes' thickness, 2e-5 of the scale in
//! f32 against 1e-9 in f64: a ray that ends or starts closer to a plane than that also visits the
//! leaf across it on the GPU and tests its triangles. Where lights or the camera sit on a split
//! plane under dense leaves, that dominates: the classroom's shadow rays test 3.4x the CPU's
//! triangles at 15 % more nodes (its lights lie 9.5e-8 m below a stored plane, under the lamps'
//! fans; see `kdtree.wgsl` and tests/it/kdtree_work_counts.rs); with lights and camera off the
//! planes they agree within 1 %. Neither walk mailboxes: a triangle in several leaves is tested
//! once per leaf on both.

use serde::{Deserialize, Serialize};
use std::cell::Cell;
use std::ops::{Add, AddAssign};

/// What a set of queries cost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Work {
    /// Queries asked of the scene (closest hit or any hit).
    pub queries: u64,
    /// Traversal steps: BVH or kd-tree nodes visited, the field's tiles and tile-BSP nodes.
    pub nodes: u64,
    /// Primitive intersection tests: triangles and analytic shapes.
    pub primitives: u64,
}

impl Work {
    /// Nothing.
    pub const ZERO: Work = Work {
        queries: 0,
        nodes: 0,
        primitives: 0,
    };
}

impl Add for Work {
    type Output = Work;
    fn add(self, o: Work) -> Work {
        Work {
            queries: self.queries + o.queries,
            nodes: self.nodes + o.nodes,
            primitives: self.primitives + o.primitives,
        }
    }
}

impl AddAssign for Work {
    fn add_assign(&mut self, o: Work) {
        *self = *self + o;
    }
}

impl std::iter::Sum for Work {
    fn sum<I: Iterator<Item = Work>>(iter: I) -> Work {
        iter.fold(Work::ZERO, Add::add)
    }
}

thread_local! {
    static TALLY: Cell<Work> = const { Cell::new(Work::ZERO) };
}

/// Counts one query asked of the scene (closest or any hit, over shapes and structure).
#[inline]
pub fn query() {
    TALLY.with(|t| {
        let w = t.get();
        t.set(Work {
            queries: w.queries + 1,
            ..w
        })
    });
}

/// Adds traversal steps and primitive tests to this thread's tally.
#[inline]
pub fn add(nodes: u64, primitives: u64) {
    TALLY.with(|t| {
        let w = t.get();
        t.set(Work {
            queries: w.queries,
            nodes: w.nodes + nodes,
            primitives: w.primitives + primitives,
        })
    });
}

/// This thread's tally since the last take, reset.
pub fn take() -> Work {
    TALLY.with(|t| t.replace(Work::ZERO))
}

/// `f`'s result and the work it did. `f` must run on this thread from start to end without
/// yielding to other tasks (no rayon join inside), as a pixel's computation does.
pub fn counted<R>(f: impl FnOnce() -> R) -> (R, Work) {
    take();
    let r = f();
    (r, take())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_computation_counts_only_its_own_work() {
        add(3, 4);
        let (r, w) = counted(|| {
            query();
            add(2, 1);
            add(0, 5);
            7
        });
        assert_eq!(r, 7);
        assert_eq!(
            w,
            Work {
                queries: 1,
                nodes: 2,
                primitives: 6
            }
        );
        assert_eq!(take(), Work::ZERO);
    }
}
