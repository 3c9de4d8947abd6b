// conemesh-cgal-check: an outside witness for conemesh's mesh verdicts (issue 5).
//
// Reads one mesh as a polygon soup (so that face i of the output is face i of the file),
// and prints one JSON object with CGAL's verdicts: validity as a polygon mesh, closedness,
// triangle-only, counts, components, boundary cycles, Euler characteristic, exact
// self-intersections (Epick predicates), degenerate faces; optionally the approximate
// Hausdorff distance to a second mesh (both directions) and, for a 2D mesh, whether every
// triangle is positively oriented and whether the boundary polygon is simple.
//
// Usage:
//   conemesh-cgal-check MESH [--hausdorff OTHER] [--grid-spacing H] [--planar]
//
// One translation unit on purpose: the CGAL headers dominate build time.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/version.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <numeric>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace PMP = CGAL::Polygon_mesh_processing;

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef K::Point_3 Point_3;
typedef K::Point_2 Point_2;
typedef CGAL::Surface_mesh<Point_3> Mesh;
typedef Mesh::Face_index Face;
typedef std::vector<std::size_t> Polygon;
typedef std::pair<std::size_t, std::size_t> FacePair;

// ---------------------------------------------------------------------------------------
// Small JSON writer (keys in insertion order, doubles round-trip exactly).

struct Json {
  std::ostringstream s;
  bool first = true;
  Json() { s << "{"; }
  void key(const std::string& k) {
    s << (first ? "\n  " : ",\n  ") << '"' << k << "\": ";
    first = false;
  }
  void b(const std::string& k, bool v) { key(k); s << (v ? "true" : "false"); }
  void n(const std::string& k, long long v) { key(k); s << v; }
  void d(const std::string& k, double v) {
    key(k);
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    s << buf;
  }
  void str(const std::string& k, const std::string& v) { key(k); s << '"' << v << '"'; }
  void null(const std::string& k) { key(k); s << "null"; }
  void raw(const std::string& k, const std::string& v) { key(k); s << v; }
  std::string done() { s << "\n}"; return s.str(); }
};

static std::string list(const std::vector<std::size_t>& v) {
  std::ostringstream s;
  s << "[";
  for (std::size_t i = 0; i < v.size(); ++i) s << (i ? ", " : "") << v[i];
  s << "]";
  return s.str();
}

static std::string pairs(const std::vector<FacePair>& v) {
  std::ostringstream s;
  s << "[";
  for (std::size_t i = 0; i < v.size(); ++i)
    s << (i ? ", " : "") << "[" << v[i].first << ", " << v[i].second << "]";
  s << "]";
  return s.str();
}

[[noreturn]] static void fail(const std::string& msg) {
  std::cerr << "conemesh-cgal-check: " << msg << "\n";
  std::exit(2);
}

// ---------------------------------------------------------------------------------------
// Input.

struct Soup {
  std::vector<Point_3> points;
  std::vector<Polygon> polygons;
};

static Soup read_soup(const std::string& path) {
  Soup s;
  if (!CGAL::IO::read_polygon_soup(path, s.points, s.polygons))
    fail(path + ": CGAL::IO::read_polygon_soup failed (unsupported or malformed file)");
  for (std::size_t f = 0; f < s.polygons.size(); ++f)
    for (std::size_t v : s.polygons[f])
      if (v >= s.points.size())
        fail(path + ": face " + std::to_string(f) + " references vertex " + std::to_string(v) +
             " of " + std::to_string(s.points.size()));
  return s;
}

static bool triangle_only(const Soup& s) {
  return std::all_of(s.polygons.begin(), s.polygons.end(),
                     [](const Polygon& p) { return p.size() == 3; });
}

// Build a Surface_mesh whose face i is polygon i and vertex i is point i (CGAL's
// polygon_soup_to_polygon_mesh adds points and polygons in order). Only for valid soups.
static Mesh to_mesh(const Soup& s) {
  Mesh m;
  PMP::polygon_soup_to_polygon_mesh(s.points, s.polygons, m);
  if (m.number_of_faces() != s.polygons.size() || m.number_of_vertices() != s.points.size())
    fail("polygon_soup_to_polygon_mesh changed the element counts; indices would not match");
  for (std::size_t f = 0; f < s.polygons.size(); ++f) {
    // Face f must have the same vertex cycle as polygon f (up to rotation).
    Face fd(static_cast<Mesh::size_type>(f));
    std::vector<std::size_t> cyc;
    for (auto v : CGAL::vertices_around_face(m.halfedge(fd), m)) cyc.push_back(std::size_t(v));
    const Polygon& p = s.polygons[f];
    auto it = std::find(cyc.begin(), cyc.end(), p[0]);
    if (cyc.size() != p.size() || it == cyc.end()) fail("face index mismatch at face " + std::to_string(f));
    std::rotate(cyc.begin(), it, cyc.end());
    if (cyc != p) fail("face index mismatch at face " + std::to_string(f));
  }
  return m;
}

// ---------------------------------------------------------------------------------------
// Self-intersections on a soup.
//
// CGAL 5.5 (Debian 12) has no triangle_soup_self_intersections, and PMP::self_intersections
// needs a valid Surface_mesh. For soups that are not polygon meshes (non-manifold edges,
// flipped faces, pinched vertices) this is a line-by-line replica of CGAL 5.5's
// internal::do_faces_intersect (self_intersections.h), with "shared edge" / "shared
// vertex" decided by vertex index instead of by halfedge adjacency. Same exact Epick
// predicates, same semantics: degenerate (collinear) faces are reported as (f, f) and not
// tested further; faces sharing an edge intersect iff coplanar and folded onto each other;
// faces sharing a vertex intersect iff an opposite edge meets the other triangle. On valid
// meshes the program checks that this replica agrees with PMP::self_intersections.

static bool soup_faces_intersect(const Soup& s, std::size_t f, std::size_t g) {
  const Polygon& a = s.polygons[f];
  const Polygon& b = s.polygons[g];
  const auto& P = s.points;
  // Shared edge: two common vertex indices.
  std::vector<std::size_t> common;
  for (std::size_t x : a)
    if (std::find(b.begin(), b.end(), x) != b.end()) common.push_back(x);
  if (common.size() == 3) return true;  // duplicate face: overlaps entirely
  if (common.size() == 2) {
    std::size_t c = a[0] + a[1] + a[2] - common[0] - common[1];
    std::size_t d = b[0] + b[1] + b[2] - common[0] - common[1];
    const Point_3 &p = P[common[0]], &q = P[common[1]];
    return CGAL::coplanar(p, q, P[c], P[d]) &&
           CGAL::coplanar_orientation(p, q, P[c], P[d]) == CGAL::POSITIVE;
  }
  K::Triangle_3 ta(P[a[0]], P[a[1]], P[a[2]]);
  K::Triangle_3 tb(P[b[0]], P[b[1]], P[b[2]]);
  if (common.size() == 1) {
    int i = int(std::find(a.begin(), a.end(), common[0]) - a.begin());
    int j = int(std::find(b.begin(), b.end(), common[0]) - b.begin());
    K::Segment_3 sa(P[a[(i + 1) % 3]], P[a[(i + 2) % 3]]);
    K::Segment_3 sb(P[b[(j + 1) % 3]], P[b[(j + 2) % 3]]);
    return CGAL::do_intersect(ta, sb) || CGAL::do_intersect(tb, sa);
  }
  return CGAL::do_intersect(ta, tb);
}

static std::vector<FacePair> soup_self_intersections(const Soup& s) {
  typedef CGAL::Box_intersection_d::Box_with_info_d<double, 3, std::size_t,
                                                    CGAL::Box_intersection_d::ID_EXPLICIT>
      Box;
  std::vector<FacePair> out;
  std::vector<Box> boxes;
  for (std::size_t f = 0; f < s.polygons.size(); ++f) {
    const Polygon& t = s.polygons[f];
    const Point_3 &p = s.points[t[0]], &q = s.points[t[1]], &r = s.points[t[2]];
    if (CGAL::collinear(p, q, r))
      out.emplace_back(f, f);
    else
      boxes.push_back(Box(p.bbox() + q.bbox() + r.bbox(), f));
  }
  CGAL::box_self_intersection_d<CGAL::Sequential_tag>(
      boxes.begin(), boxes.end(), [&](const Box& x, const Box& y) {
        if (soup_faces_intersect(s, x.info(), y.info())) out.emplace_back(x.info(), y.info());
      });
  return out;
}

static void canonical(std::vector<FacePair>& v) {
  for (auto& p : v)
    if (p.first > p.second) std::swap(p.first, p.second);
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

// ---------------------------------------------------------------------------------------
// Topology.

struct Topo {
  std::size_t referenced_vertices = 0, edges = 0, components = 0, boundary_cycles = 0;
  bool closed = false;
  long long euler = 0;
};

static Topo mesh_topology(Mesh& m) {
  Topo t;
  for (auto v : m.vertices())
    if (!m.is_isolated(v)) ++t.referenced_vertices;
  t.edges = m.number_of_edges();
  auto fcc = m.add_property_map<Face, std::size_t>("f:cc", 0).first;
  t.components = PMP::connected_components(m, fcc);
  std::vector<bool> seen(m.number_of_halfedges(), false);
  for (auto h : m.halfedges()) {
    if (!m.is_border(h) || seen[std::size_t(h)]) continue;
    ++t.boundary_cycles;
    for (auto g : CGAL::halfedges_around_face(h, m)) seen[std::size_t(g)] = true;
  }
  t.closed = CGAL::is_closed(m);
  t.euler = (long long)t.referenced_vertices - (long long)t.edges + (long long)m.number_of_faces();
  return t;
}

// For soups that are not polygon meshes: referenced vertices, unique undirected edges and
// edge-connected components counted directly on the indices (not a CGAL function; an
// independent count).
static Topo soup_topology(const Soup& s) {
  Topo t;
  std::vector<bool> used(s.points.size(), false);
  std::vector<std::array<std::size_t, 3>> he;  // (min, max, face)
  for (std::size_t f = 0; f < s.polygons.size(); ++f) {
    const Polygon& p = s.polygons[f];
    for (std::size_t i = 0; i < p.size(); ++i) {
      used[p[i]] = true;
      std::size_t a = p[i], b = p[(i + 1) % p.size()];
      he.push_back({std::min(a, b), std::max(a, b), f});
    }
  }
  t.referenced_vertices = std::count(used.begin(), used.end(), true);
  std::sort(he.begin(), he.end());
  std::vector<std::size_t> parent(s.polygons.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (std::size_t i = 0; i < he.size();) {
    std::size_t j = i;
    while (j < he.size() && he[j][0] == he[i][0] && he[j][1] == he[i][1]) {
      parent[find(he[j][2])] = find(he[i][2]);
      ++j;
    }
    ++t.edges;
    i = j;
  }
  for (std::size_t f = 0; f < parent.size(); ++f)
    if (find(f) == f) ++t.components;
  t.euler = (long long)t.referenced_vertices - (long long)t.edges + (long long)s.polygons.size();
  return t;
}

// ---------------------------------------------------------------------------------------
// Planar (2D) mode.

struct Planar {
  std::string source;
  std::vector<Point_2> points;
  std::vector<Polygon> triangles;
};

// OBJ with `vt`: the 2D mesh is made of the texture-coordinate indices of the faces.
static bool read_obj_uv(const std::string& path, Planar& out) {
  std::ifstream in(path);
  if (!in) return false;
  std::string line;
  std::vector<Point_2> vt;
  std::vector<Polygon> faces;
  bool all_have_vt = true;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "vt") {
      double u, v;
      ls >> u >> v;
      vt.emplace_back(u, v);
    } else if (tag == "f") {
      Polygon p;
      std::string corner;
      while (ls >> corner) {
        auto slash = corner.find('/');
        if (slash == std::string::npos || slash + 1 >= corner.size() || corner[slash + 1] == '/') {
          all_have_vt = false;
          break;
        }
        long long k = std::atoll(corner.c_str() + slash + 1);
        if (k < 0) k = (long long)vt.size() + k + 1;
        if (k < 1 || (std::size_t)k > vt.size()) fail(path + ": vt index out of range in face");
        p.push_back(std::size_t(k - 1));
      }
      faces.push_back(p);
    }
  }
  if (vt.empty() || !all_have_vt) return false;
  out.source = "obj_vt";
  out.points = vt;
  out.triangles = faces;
  return true;
}

static std::string planar_json(const Planar& pl) {
  Json j;
  j.str("source", pl.source);
  j.n("vertices", (long long)pl.points.size());
  j.n("triangles", (long long)pl.triangles.size());
  std::vector<std::size_t> non_positive;
  bool tri_only = true;
  for (std::size_t f = 0; f < pl.triangles.size(); ++f) {
    const Polygon& t = pl.triangles[f];
    if (t.size() != 3) { tri_only = false; non_positive.push_back(f); continue; }
    // Exact orientation (Epick filtered predicate): positive = counter-clockwise.
    if (CGAL::orientation(pl.points[t[0]], pl.points[t[1]], pl.points[t[2]]) != CGAL::LEFT_TURN)
      non_positive.push_back(f);
  }
  j.b("triangle_only", tri_only);
  j.b("all_positively_oriented", non_positive.empty());
  j.raw("non_positive_faces", list(non_positive));
  bool pm = PMP::is_polygon_soup_a_polygon_mesh(pl.triangles);
  j.b("valid_polygon_mesh", pm);
  if (!pm) {
    j.null("boundary_loops");
    j.null("boundary_simple");
    return j.done();
  }
  Soup s;
  for (const auto& p : pl.points) s.points.emplace_back(p.x(), p.y(), 0.0);
  s.polygons = pl.triangles;
  Mesh m = to_mesh(s);
  std::vector<bool> seen(m.number_of_halfedges(), false);
  std::size_t loops = 0;
  bool all_simple = true;
  std::vector<std::size_t> sizes;
  std::vector<std::string> orient;
  for (auto h : m.halfedges()) {
    if (!m.is_border(h) || seen[std::size_t(h)]) continue;
    ++loops;
    std::vector<Point_2> poly;
    for (auto g : CGAL::halfedges_around_face(h, m)) {
      seen[std::size_t(g)] = true;
      poly.push_back(pl.points[std::size_t(m.target(g))]);
    }
    sizes.push_back(poly.size());
    // Exact (Epick predicates) simplicity test of the loop as a polygon.
    bool simple = CGAL::is_simple_2(poly.begin(), poly.end(), K());
    all_simple = all_simple && simple;
    // The border halfedges run against the faces, so an outer boundary is clockwise here.
    orient.push_back(!simple ? "\"not simple\""
                     : CGAL::orientation_2(poly.begin(), poly.end(), K()) == CGAL::CLOCKWISE
                         ? "\"cw (faces ccw inside)\""
                         : "\"ccw (hole or flipped)\"");
  }
  j.n("boundary_loops", (long long)loops);
  j.raw("boundary_loop_sizes", list(sizes));
  std::string o = "[";
  for (std::size_t i = 0; i < orient.size(); ++i) o += (i ? ", " : "") + orient[i];
  j.raw("boundary_loop_orientation", o + "]");
  j.b("boundary_simple", all_simple);
  return j.done();
}

// ---------------------------------------------------------------------------------------

static double bbox_diagonal(const std::vector<Point_3>& pts) {
  if (pts.empty()) return 0.0;
  CGAL::Bbox_3 b = pts[0].bbox();
  for (const auto& p : pts) b += p.bbox();
  return std::sqrt(CGAL::square(b.xmax() - b.xmin()) + CGAL::square(b.ymax() - b.ymin()) +
                   CGAL::square(b.zmax() - b.zmin()));
}

static void usage() {
  std::cerr << "usage: conemesh-cgal-check MESH [--hausdorff OTHER] [--grid-spacing H] [--planar]\n"
               "  MESH/OTHER: OFF, OBJ, PLY, STL (CGAL::IO::read_polygon_soup)\n"
               "  --hausdorff OTHER  approximate Hausdorff distance both ways (grid sampling)\n"
               "  --grid-spacing H   sampling grid spacing (default 0.002 x max bbox diagonal)\n"
               "  --planar           2D checks on OBJ vt, or on x,y when every z is 0\n";
  std::exit(2);
}

int main(int argc, char** argv) {
  std::string mesh_path, other_path;
  double grid = 0.0;
  bool planar = false;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--hausdorff" && i + 1 < argc) other_path = argv[++i];
    else if (a == "--grid-spacing" && i + 1 < argc) grid = std::atof(argv[++i]);
    else if (a == "--planar") planar = true;
    else if (a == "-h" || a == "--help") usage();
    else if (!a.empty() && a[0] == '-') usage();
    else if (mesh_path.empty()) mesh_path = a;
    else usage();
  }
  if (mesh_path.empty()) usage();

  Soup s = read_soup(mesh_path);
  Json j;
  j.str("cgal_version", CGAL_VERSION_STR);
  j.str("file", mesh_path);
  const bool pm = PMP::is_polygon_soup_a_polygon_mesh(s.polygons);
  const bool tri = triangle_only(s);
  j.b("valid_polygon_mesh", pm);
  j.b("triangle_only", tri);
  j.n("vertices", (long long)s.points.size());
  j.n("faces", (long long)s.polygons.size());

  std::vector<FacePair> si;
  std::vector<std::size_t> degenerate;
  Mesh m;
  if (pm) {
    m = to_mesh(s);
    Topo t = mesh_topology(m);
    j.str("topology_source", "Surface_mesh");
    j.n("referenced_vertices", (long long)t.referenced_vertices);
    j.n("edges", (long long)t.edges);
    j.b("closed", t.closed);
    j.n("connected_components", (long long)t.components);
    j.n("boundary_cycles", (long long)t.boundary_cycles);
    j.n("euler_characteristic", t.euler);
  } else {
    // Not a polygon mesh: CGAL cannot build a Surface_mesh, so closedness and boundary
    // cycles are undefined here; counts come from the soup itself.
    Topo t = soup_topology(s);
    j.str("topology_source", "soup");
    j.n("referenced_vertices", (long long)t.referenced_vertices);
    j.n("edges", (long long)t.edges);
    j.null("closed");
    j.n("connected_components", (long long)t.components);
    j.null("boundary_cycles");
    j.n("euler_characteristic", t.euler);
  }

  if (tri) {
    for (std::size_t f = 0; f < s.polygons.size(); ++f) {
      const Polygon& p = s.polygons[f];
      bool deg = pm ? PMP::is_degenerate_triangle_face(Face(Mesh::size_type(f)), m)
                    : CGAL::collinear(s.points[p[0]], s.points[p[1]], s.points[p[2]]);
      if (deg) degenerate.push_back(f);
    }
    std::string method;
    if (pm) {
      std::vector<std::pair<Face, Face>> out;
      PMP::self_intersections(m, std::back_inserter(out));
      for (auto& p : out) si.emplace_back(std::size_t(p.first), std::size_t(p.second));
      canonical(si);
      method = "PMP::self_intersections";
      std::vector<FacePair> replica = soup_self_intersections(s);
      canonical(replica);
      j.b("soup_replica_agrees", replica == si);
    } else {
      si = soup_self_intersections(s);
      canonical(si);
      method = "soup replica of CGAL 5.5 PMP::internal::do_faces_intersect";
    }
    j.str("self_intersection_method", method);
    // PMP::does_self_intersect is true iff self_intersections is non-empty (it also counts
    // degenerate faces, reported as (f, f)).
    j.b("self_intersects", !si.empty());
    j.raw("self_intersecting_pairs", pairs(si));
    j.raw("degenerate_faces", list(degenerate));
  } else {
    j.null("self_intersects");
    j.null("self_intersecting_pairs");
    j.null("degenerate_faces");
  }

  if (!other_path.empty()) {
    Soup o = read_soup(other_path);
    if (!pm || !tri || !PMP::is_polygon_soup_a_polygon_mesh(o.polygons) || !triangle_only(o))
      fail("--hausdorff needs two valid triangle meshes");
    Mesh mo = to_mesh(o);
    double h = grid > 0 ? grid : 0.002 * std::max(bbox_diagonal(s.points), bbox_diagonal(o.points));
    // Grid sampling (deterministic): faces on a grid of spacing h, edges split every h,
    // vertices included. The distance to a mesh is 1-Lipschitz and every surface point is
    // within h of a sample, so each one-sided value v satisfies v <= true <= v + h.
    auto np = CGAL::parameters::use_grid_sampling(true).grid_spacing(h);
    double ab = PMP::approximate_Hausdorff_distance<CGAL::Sequential_tag>(m, mo, np);
    double ba = PMP::approximate_Hausdorff_distance<CGAL::Sequential_tag>(mo, m, np);
    Json hj;
    hj.str("other", other_path);
    hj.str("sampling", "grid (use_grid_sampling, vertices + edges + faces)");
    hj.d("grid_spacing", h);
    hj.d("mesh_to_other", ab);
    hj.d("other_to_mesh", ba);
    hj.d("symmetric", std::max(ab, ba));
    hj.d("error_bound", h);
    std::string hs = hj.done();
    j.raw("hausdorff", hs);
  }

  if (planar) {
    Planar pl;
    std::string ext = mesh_path.size() >= 4 ? mesh_path.substr(mesh_path.size() - 4) : "";
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (!(ext == ".obj" && read_obj_uv(mesh_path, pl))) {
      for (std::size_t v = 0; v < s.points.size(); ++v)
        if (s.points[v].z() != 0.0)
          fail("--planar: vertex " + std::to_string(v) + " has z != 0 and the file has no vt");
      pl.source = "xy";
      for (const auto& p : s.points) pl.points.emplace_back(p.x(), p.y());
      pl.triangles = s.polygons;
    }
    j.raw("planar", planar_json(pl));
  }

  std::cout << j.done() << std::endl;
  return 0;
}
