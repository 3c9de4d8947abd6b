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

/// A value per element, indexed by the element's typed id: per-face state is a
/// [`FaceMap`], per-vertex state a [`VertexMap`]. The working mesh's arrays change in two
/// ways only, and these are the map's operations: new elements are appended
/// ([`IdMap::push`], [`IdMap::extend`]) and removed ones dropped with the others' order kept
/// ([`IdMap::drop_marked`], [`IdMap::compact`]), so every map kept in step with a mesh
/// follows it the same way.
#[derive(Clone, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct IdMap<I, T> {
    values: Vec<T>,
    #[serde(skip)]
    id: std::marker::PhantomData<fn(I) -> I>,
}

/// A value per face, indexed by [`FaceId`].
pub type FaceMap<T> = IdMap<FaceId, T>;
/// A value per vertex, indexed by [`VertexId`].
pub type VertexMap<T> = IdMap<VertexId, T>;

/// An id that indexes an [`IdMap`].
pub trait ElementId: Copy {
    /// The id as an array index.
    fn index(self) -> usize;
}

impl ElementId for FaceId {
    #[inline]
    fn index(self) -> usize {
        self.idx()
    }
}

impl ElementId for VertexId {
    #[inline]
    fn index(self) -> usize {
        self.idx()
    }
}

impl<I, T> IdMap<I, T> {
    /// The map holding `values`, the value of element `i` at position `i`.
    pub fn from_vec(values: Vec<T>) -> Self {
        IdMap {
            values,
            id: std::marker::PhantomData,
        }
    }

    /// `n` elements, each with `value`.
    pub fn filled(n: usize, value: T) -> Self
    where
        T: Clone,
    {
        Self::from_vec(vec![value; n])
    }

    /// The values in element order.
    pub fn into_vec(self) -> Vec<T> {
        self.values
    }

    /// The values in element order.
    pub fn as_slice(&self) -> &[T] {
        &self.values
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// No element.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The values in element order.
    pub fn iter(&self) -> std::slice::Iter<'_, T> {
        self.values.iter()
    }

    /// The values in element order.
    pub fn iter_mut(&mut self) -> std::slice::IterMut<'_, T> {
        self.values.iter_mut()
    }

    /// The values in element order.
    pub fn as_mut_slice(&mut self) -> &mut [T] {
        &mut self.values
    }

    /// No element (the memory is kept for the next values).
    pub fn clear(&mut self) {
        self.values.clear();
    }

    /// A new element's value (its id is the old length).
    pub fn push(&mut self, value: T) {
        self.values.push(value);
    }

    /// `n` elements: a map behind its mesh catches up with `value` for the missing
    /// elements' values; one ahead drops its last values.
    pub fn resize(&mut self, n: usize, value: T)
    where
        T: Clone,
    {
        self.values.resize(n, value);
    }

    /// Drop the elements marked in `gone` (`gone[i]`: element `i` is removed), keeping the
    /// others in order: their ids shift down past the removed ones, as the faces' do when a
    /// patch is stitched.
    pub fn drop_marked(&mut self, gone: &[bool]) {
        debug_assert!(gone.len() >= self.values.len());
        let mut k = 0;
        self.values.retain(|_| {
            k += 1;
            !gone[k - 1]
        });
    }
}

impl<I: ElementId, T> IdMap<I, T> {
    /// The value of element `id`, `None` past the end.
    #[inline]
    pub fn get(&self, id: I) -> Option<&T> {
        self.values.get(id.index())
    }

    /// The value of element `id` to change, `None` past the end.
    #[inline]
    pub fn get_mut(&mut self, id: I) -> Option<&mut T> {
        self.values.get_mut(id.index())
    }

    /// Follow an old → new id map that keeps the order (`map[old]`: the element's new id,
    /// `None`: dropped), as [`crate::mesh::TriMesh::without_unreferenced_vertices`] makes;
    /// a kept element past the end of the values gets `fill`.
    pub fn compact(&mut self, map: &[Option<I>], fill: T)
    where
        T: Clone,
    {
        self.values.resize(map.len(), fill);
        let mut old = 0;
        self.values.retain(|_| {
            old += 1;
            debug_assert!(map[old - 1].is_none_or(|n| n.index() < old));
            map[old - 1].is_some()
        });
    }
}

impl<I, T> Default for IdMap<I, T> {
    fn default() -> Self {
        Self::from_vec(Vec::new())
    }
}

impl<I, T: fmt::Debug> fmt::Debug for IdMap<I, T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&self.values, f)
    }
}

impl<I: ElementId, T> std::ops::Index<I> for IdMap<I, T> {
    type Output = T;
    #[inline]
    fn index(&self, id: I) -> &T {
        &self.values[id.index()]
    }
}

impl<I: ElementId, T> std::ops::IndexMut<I> for IdMap<I, T> {
    #[inline]
    fn index_mut(&mut self, id: I) -> &mut T {
        &mut self.values[id.index()]
    }
}

impl<I, T> FromIterator<T> for IdMap<I, T> {
    fn from_iter<It: IntoIterator<Item = T>>(iter: It) -> Self {
        Self::from_vec(iter.into_iter().collect())
    }
}

impl<I, T> Extend<T> for IdMap<I, T> {
    fn extend<It: IntoIterator<Item = T>>(&mut self, iter: It) {
        self.values.extend(iter);
    }
}

impl<'a, I, T> IntoIterator for &'a IdMap<I, T> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;
    fn into_iter(self) -> Self::IntoIter {
        self.values.iter()
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

    #[test]
    fn id_maps_follow_removals_and_compaction() {
        let mut faces: FaceMap<char> = "abcde".chars().collect();
        faces.drop_marked(&[false, true, false, true, false]);
        assert_eq!(faces.as_slice(), &['a', 'c', 'e']);
        faces.push('f');
        assert_eq!(faces[FaceId(3)], 'f');
        assert_eq!(faces.get(FaceId(4)), None);
        let mut vertices: VertexMap<u32> = VertexMap::from_vec(vec![10, 11, 12, 13]);
        let map = [Some(VertexId(0)), None, Some(VertexId(1))];
        vertices.compact(&map, 0);
        assert_eq!(
            vertices.as_slice(),
            &[10, 12],
            "past the map's end: dropped"
        );
        vertices[VertexId(1)] += 1;
        assert_eq!(vertices.as_slice(), &[10, 13]);
        vertices.compact(&[None, Some(VertexId(0)), Some(VertexId(1))], 1);
        assert_eq!(
            vertices.into_vec(),
            vec![13, 1],
            "kept past the values' end: filled"
        );
    }
}
