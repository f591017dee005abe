//! Disjoint pieces of a graph's nodes: union–find with path halving, for the partition
//! crossover's components (`merge`) and the α ascent's joined graph (`alpha`).

/// Each node's link towards its piece's root (a root links to itself).
pub(crate) struct Pieces(Vec<u32>);

impl Pieces {
    /// `n` nodes, each a piece of its own.
    pub(crate) fn new(n: usize) -> Pieces {
        Pieces((0..n as u32).collect())
    }

    /// The root of `v`'s piece (halving the path on the way).
    pub(crate) fn root(&mut self, mut v: u32) -> u32 {
        while self.0[v as usize] != v {
            self.0[v as usize] = self.0[self.0[v as usize] as usize];
            v = self.0[v as usize];
        }
        v
    }

    /// Joins the pieces of `a` and `b` (`a`'s root then links to `b`'s); false when they were
    /// one piece already.
    pub(crate) fn join(&mut self, a: u32, b: u32) -> bool {
        let (ra, rb) = (self.root(a), self.root(b));
        if ra != rb {
            self.0[ra as usize] = rb;
        }
        ra != rb
    }
}
