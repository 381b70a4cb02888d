// Marching-cubes look-up tables (the edge table ξ and triangle table Λ of Feltell & Bai §2.2),
// generated at compile time from a face-consistent disambiguation rule instead of being pasted in.
//
// Numbering (shared by every mesh file):
//   Corner c (0..7) sits at offset (c & 1, (c >> 1) & 1, (c >> 2) & 1) from the cell's minimum
//   corner. Bit c of a case index is set when corner c is inside (φ < 0, see is_inside()).
//   Edge e = 4 * axis + k (axis 0 = x, 1 = y, 2 = z) runs from its start corner one step along
//   +axis; k encodes the start corner's two other coordinates in increasing axis order:
//     x-edges: k = y + 2z   e0 (0,0,0)  e1 (0,1,0)  e2 (0,0,1)  e3 (0,1,1)
//     y-edges: k = x + 2z   e4 (0,0,0)  e5 (1,0,0)  e6 (0,0,1)  e7 (1,0,1)
//     z-edges: k = x + 2y   e8 (0,0,0)  e9 (1,0,0)  e10 (0,1,0) e11 (1,1,0)
//   so the vertex of edge e of the cell with minimum corner c is the lattice-edge vertex
//   G(c + start_offset(e), axis(e)).
//
// Construction. On each of the 6 cube faces, walked counter-clockwise as seen from outside the
// cube, the sign changes between consecutive corners are crossings, alternately outside->inside
// and inside->outside. Each outside->inside crossing is joined by a segment to the next
// inside->outside crossing along the walk. With two crossings this is the only choice; on an
// ambiguous face (four crossings) it always separates the two inside corners. The rule depends only
// on the four face corners, so the two cells sharing a face always cut it identically (no cracks).
// Each crossing edge lies on two faces and starts a segment on one and ends one on the other, so
// the segments chain into closed loops. Each loop is fan-triangulated from the first vertex whose
// fan has no diagonal joining two vertices on one cube face: such a diagonal could coincide with a
// triangle side built by the neighbouring cell and give an edge shared by four triangles. With
// this, a triangle side lies on a face only if it is a face segment, shared by exactly two cells. The
// segment direction makes every loop counter-clockwise seen from the outside (φ > 0) side, so
// triangle normals (b - a) x (c - a) point towards increasing φ.
#pragma once

#include <array>
#include <cstdint>

namespace liveset::mc {

inline constexpr int kCorners = 8;
inline constexpr int kEdges = 12;
inline constexpr int kCases = 256;
// Upper bound on triangles in one case; build_tables() fails to compile if it is exceeded.
inline constexpr int kMaxTriangles = 5;
inline constexpr std::int8_t kEnd = -1;  // terminator in the triangle table (the paper's NULL)

constexpr int corner_offset(int corner, int axis) { return (corner >> axis) & 1; }

struct EdgeInfo {
    int axis;          // 0, 1, 2
    int start_corner;  // corner at the edge's minimum end
    int end_corner;    // start_corner + one step along axis
};

constexpr EdgeInfo edge_info(int edge) {
    const int axis = edge / 4;
    const int k = edge % 4;
    const int u = axis == 0 ? 1 : 0;  // the two other axes in increasing order
    const int v = axis == 2 ? 1 : 2;
    const int start = ((k & 1) << u) | ((k >> 1) << v);
    return {axis, start, start | (1 << axis)};
}

// Each edge as the offset of its start corner from the cell origin and its axis (the marchers' lookup).
struct EdgeStart {
    int dx, dy, dz, axis;
};
inline constexpr std::array<EdgeStart, kEdges> kEdgeStarts = [] {
    std::array<EdgeStart, kEdges> t{};
    for (int e = 0; e < kEdges; ++e) {
        const EdgeInfo info = edge_info(e);
        t[static_cast<std::size_t>(e)] = {corner_offset(info.start_corner, 0), corner_offset(info.start_corner, 1),
                                          corner_offset(info.start_corner, 2), info.axis};
    }
    return t;
}();

// The edge joining two corners that differ along exactly one axis.
constexpr int edge_between(int c1, int c2) {
    const int diff = c1 ^ c2;
    const int axis = diff == 1 ? 0 : (diff == 2 ? 1 : 2);
    const int start = c1 < c2 ? c1 : c2;
    const int u = axis == 0 ? 1 : 0;
    const int v = axis == 2 ? 1 : 2;
    const int k = corner_offset(start, u) + 2 * corner_offset(start, v);
    return 4 * axis + k;
}

struct Tables {
    std::array<std::uint16_t, kCases> edges{};  // ξ: bit e set when edge e holds a vertex
    std::array<std::uint8_t, kCases> triangle_count{};
    int fan_failures = 0;  // loops with no valid fan start (0 for this rule; checked below)
    // Λ: 3 edge ids per triangle, kEnd-terminated.
    std::array<std::array<std::int8_t, 3 * kMaxTriangles + 1>, kCases> triangles{};
};

// True when the two cube edges lie on a common cube face.
constexpr bool edges_share_face(int e1, int e2) {
    const EdgeInfo a = edge_info(e1), b = edge_info(e2);
    for (int axis = 0; axis < 3; ++axis)
        if (axis != a.axis && axis != b.axis &&
            corner_offset(a.start_corner, axis) == corner_offset(b.start_corner, axis))
            return true;
    return false;
}

// First loop position from which a fan has no diagonal joining two vertices of one cube face
// (such a diagonal could coincide with a triangle side of the neighbouring cell), or -1.
constexpr int fan_start(const int* loop, int len) {
    for (int s = 0; s < len; ++s) {
        bool ok = true;
        for (int j = 2; j + 1 < len && ok; ++j)
            if (edges_share_face(loop[s], loop[(s + j) % len])) ok = false;
        if (ok) return s;
    }
    return -1;
}

constexpr Tables build_tables() {
    Tables t{};
    for (int cs = 0; cs < kCases; ++cs) {
        auto inside = [cs](int corner) { return ((cs >> corner) & 1) != 0; };
        std::uint16_t mask = 0;
        for (int e = 0; e < kEdges; ++e) {
            const EdgeInfo info = edge_info(e);
            if (inside(info.start_corner) != inside(info.end_corner)) mask |= static_cast<std::uint16_t>(1u << e);
        }
        t.edges[cs] = mask;

        // Segments on the faces: next[a] = b for a segment from edge a to edge b.
        std::array<int, kEdges> next{};
        for (int& n : next) n = -1;
        for (int axis = 0; axis < 3; ++axis) {
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // u x v = +axis
            for (int side = 0; side < 2; ++side) {
                // Counter-clockwise around the outward normal (+axis for side 1, -axis for side 0).
                constexpr int ccw_pos[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
                constexpr int ccw_neg[4][2] = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
                int ring[4]{};
                for (int i = 0; i < 4; ++i) {
                    const int* uv = side == 1 ? ccw_pos[i] : ccw_neg[i];
                    ring[i] = (side << axis) | (uv[0] << u) | (uv[1] << v);
                }
                int cross_edge[4]{};
                bool out_to_in[4]{};
                int n = 0;
                for (int i = 0; i < 4; ++i) {
                    const int a = ring[i], b = ring[(i + 1) % 4];
                    if (inside(a) != inside(b)) {
                        cross_edge[n] = edge_between(a, b);
                        out_to_in[n] = !inside(a);
                        ++n;
                    }
                }
                for (int i = 0; i < n; ++i) {
                    if (!out_to_in[i]) continue;
                    for (int j = 1; j < n; ++j) {
                        const int k = (i + j) % n;
                        if (!out_to_in[k]) {
                            next[cross_edge[i]] = cross_edge[k];
                            break;
                        }
                    }
                }
            }
        }

        // Chain segments into loops and fan-triangulate each loop.
        bool visited[kEdges]{};
        int tri = 0;
        for (int e = 0; e < kEdges; ++e) {
            if (!((mask >> e) & 1) || visited[e]) continue;
            int loop[kEdges]{};
            int len = 0;
            for (int cur = e; !visited[cur]; cur = next[cur]) {
                visited[cur] = true;
                loop[len++] = cur;
            }
            const int s = fan_start(loop, len);
            if (s < 0) t.fan_failures++;
            const int s0 = s < 0 ? 0 : s;
            for (int i = 1; i + 1 < len; ++i) {
                t.triangles[cs][3 * tri + 0] = static_cast<std::int8_t>(loop[s0]);
                t.triangles[cs][3 * tri + 1] = static_cast<std::int8_t>(loop[(s0 + i) % len]);
                t.triangles[cs][3 * tri + 2] = static_cast<std::int8_t>(loop[(s0 + i + 1) % len]);
                ++tri;
            }
        }
        t.triangle_count[cs] = static_cast<std::uint8_t>(tri);
        t.triangles[cs][3 * tri] = kEnd;
    }
    return t;
}

inline constexpr Tables kTables = build_tables();
static_assert(kTables.fan_failures == 0, "every loop must have a fan without same-face diagonals");

}  // namespace liveset::mc
