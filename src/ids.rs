//! Typed element handles (spade/parry habit): `u32` newtypes instead of raw `usize`.
//!
//! `Display` prints the short names used in every error and report: `v12`, `f7`, `h3`, `p2`,
//! so that a failure message names elements that can be looked up in the input file
//! (ids are 0-based positions in the mesh arrays).

use serde::{Deserialize, Serialize};
use std::fmt;

macro_rules! define_id {
    ($(#[$doc:meta])* $name:ident, $prefix:literal) => {
        $(#[$doc])*
        #[derive(Copy, Clone, PartialEq, Eq, PartialOrd, Ord, Hash, Default, Serialize, Deserialize)]
        #[serde(transparent)]
        pub struct $name(pub u32);

        impl $name {
            /// The id as an array index.
            #[inline]
            pub fn idx(self) -> usize {
                self.0 as usize
            }

            /// Id from an array index. Panics only if `i` does not fit in `u32`; mesh
            /// constructors refuse meshes that large with a typed error first.
            #[inline]
            pub fn new(i: usize) -> Self {
                debug_assert!(i <= u32::MAX as usize);
                $name(i as u32)
            }
        }

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                write!(f, concat!($prefix, "{}"), self.0)
            }
        }

        impl fmt::Debug for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                fmt::Display::fmt(self, f)
            }
        }

        impl From<$name> for usize {
            fn from(id: $name) -> usize {
                id.idx()
            }
        }
    };
}

define_id!(
    /// A vertex of a [`crate::TriMesh`] (index into `positions`).
    VertexId,
    "v"
);
define_id!(
    /// A triangle of a [`crate::TriMesh`] (index into `triangles`).
    FaceId,
    "f"
);
define_id!(
    /// A half-edge: `3·f + i` is the directed edge `triangles[f][i] → triangles[f][(i+1)%3]`.
    HalfedgeId,
    "h"
);
define_id!(
    /// A patch of Algorithm 1 (order of creation).
    PatchId,
    "p"
);

impl HalfedgeId {
    /// The half-edge `i` (0..3) of face `f`.
    #[inline]
    pub fn of(f: FaceId, i: usize) -> Self {
        HalfedgeId(f.0 * 3 + i as u32)
    }
    /// The face this half-edge belongs to.
    #[inline]
    pub fn face(self) -> FaceId {
        FaceId(self.0 / 3)
    }
    /// Position (0..3) inside its face.
    #[inline]
    pub fn local(self) -> usize {
        (self.0 % 3) as usize
    }
    /// Next half-edge inside the same face.
    #[inline]
    pub fn next(self) -> Self {
        HalfedgeId::of(self.face(), (self.local() + 1) % 3)
    }
    /// Previous half-edge inside the same face.
    #[inline]
    pub fn prev(self) -> Self {
        HalfedgeId::of(self.face(), (self.local() + 2) % 3)
    }
}

/// An undirected edge written as its two endpoints, smaller id first; prints `(v3, v9)`.
#[derive(Copy, Clone, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct EdgeKey(pub VertexId, pub VertexId);

impl EdgeKey {
    /// The edge between `a` and `b`, in canonical order.
    #[inline]
    pub fn new(a: VertexId, b: VertexId) -> Self {
        if a <= b {
            EdgeKey(a, b)
        } else {
            EdgeKey(b, a)
        }
    }
}

impl fmt::Display for EdgeKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}, {})", self.0, self.1)
    }
}

impl fmt::Debug for EdgeKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_print_short_names() {
        assert_eq!(VertexId(12).to_string(), "v12");
        assert_eq!(FaceId(7).to_string(), "f7");
        assert_eq!(HalfedgeId(3).to_string(), "h3");
        assert_eq!(PatchId(2).to_string(), "p2");
        assert_eq!(
            EdgeKey::new(VertexId(9), VertexId(3)).to_string(),
            "(v3, v9)"
        );
    }

    #[test]
    fn halfedge_arithmetic_cycles_inside_face() {
        let h = HalfedgeId::of(FaceId(5), 2);
        assert_eq!(h.face(), FaceId(5));
        assert_eq!(h.local(), 2);
        assert_eq!(h.next(), HalfedgeId::of(FaceId(5), 0));
        assert_eq!(h.prev(), HalfedgeId::of(FaceId(5), 1));
        assert_eq!(h.next().next().next(), h);
    }
}
