// Tests of the generated marching-cubes tables: edge table against the corner signs, triangles
// only on flagged edges, per-case loops closed and consistently oriented, winding towards φ > 0.
#include <gtest/gtest.h>

#include <map>
#include <utility>

#include "liveset/grid/vec3.hpp"
#include "liveset/mesh/mc_tables.hpp"

namespace liveset {
namespace {

using mc::kTables;

Vec3d corner_pos(int c) { return {double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)}; }

Vec3d edge_mid(int e) {
    const mc::EdgeInfo info = mc::edge_info(e);
    Vec3d p = corner_pos(info.start_corner);
    p[info.axis] += 0.5;
    return p;
}

// Two edges lie on a common cube face iff some axis coordinate is fixed to the same value on both.
bool share_face(int e1, int e2) {
    const Vec3d a = edge_mid(e1), b = edge_mid(e2);
    for (int k = 0; k < 3; ++k)
        if ((a[k] == 0 || a[k] == 1) && a[k] == b[k]) return true;
    return false;
}

TEST(McTables, EdgeNumberingMatchesHeader) {
    // e5 starts at (1,0,0) along y; e10 starts at (0,1,0) along z; e3 starts at (0,1,1) along x.
    EXPECT_EQ(mc::edge_info(5).start_corner, 1);
    EXPECT_EQ(mc::edge_info(5).axis, 1);
    EXPECT_EQ(mc::edge_info(10).start_corner, 2);
    EXPECT_EQ(mc::edge_info(10).axis, 2);
    EXPECT_EQ(mc::edge_info(3).start_corner, 6);
    for (int e = 0; e < 12; ++e) {
        const mc::EdgeInfo i = mc::edge_info(e);
        EXPECT_EQ(mc::edge_between(i.start_corner, i.end_corner), e);
        EXPECT_EQ(mc::edge_between(i.end_corner, i.start_corner), e);
    }
}

TEST(McTables, EdgeTableFlagsExactlyTheSignChanges) {
    for (int cs = 0; cs < 256; ++cs)
        for (int e = 0; e < 12; ++e) {
            const mc::EdgeInfo i = mc::edge_info(e);
            const bool differ = ((cs >> i.start_corner) & 1) != ((cs >> i.end_corner) & 1);
            EXPECT_EQ(((kTables.edges[cs] >> e) & 1) != 0, differ) << "case " << cs << " edge " << e;
        }
}

TEST(McTables, TrianglesUseEveryFlaggedEdgeAndNothingElse) {
    for (int cs = 0; cs < 256; ++cs) {
        unsigned used = 0;
        int n = 0;
        for (int j = 0; kTables.triangles[cs][j] != mc::kEnd; ++j, ++n) used |= 1u << kTables.triangles[cs][j];
        EXPECT_EQ(n % 3, 0);
        EXPECT_EQ(n / 3, kTables.triangle_count[cs]);
        EXPECT_EQ(used, kTables.edges[cs]) << "case " << cs;
    }
    EXPECT_EQ(kTables.triangle_count[0], 0);
    EXPECT_EQ(kTables.triangle_count[255], 0);
    for (int c = 0; c < 8; ++c) {
        EXPECT_EQ(kTables.triangle_count[1 << c], 1);
        EXPECT_EQ(kTables.triangle_count[255 ^ (1 << c)], 1);
    }
}

// Within a case, every triangle side is either a diagonal inside a loop (used twice, in opposite
// directions) or a boundary segment on a cube face (used once); each flagged edge starts exactly one
// boundary segment and ends exactly one, so the boundary is a set of closed loops on the faces.
TEST(McTables, CaseTrianglesFormOrientedDisksBoundedByFaceLoops) {
    for (int cs = 0; cs < 256; ++cs) {
        std::map<std::pair<int, int>, int> directed;
        const auto& t = kTables.triangles[cs];
        for (int j = 0; t[j] != mc::kEnd; j += 3)
            for (int k = 0; k < 3; ++k) ++directed[{t[j + k], t[j + (k + 1) % 3]}];
        int starts[12]{}, ends[12]{};
        for (const auto& [edge, count] : directed) {
            ASSERT_EQ(count, 1) << "case " << cs << " repeats a directed side";
            const bool has_reverse = directed.count({edge.second, edge.first}) > 0;
            if (has_reverse) {
                // Diagonals must not join two vertices of one face (the neighbour could reuse them).
                EXPECT_FALSE(share_face(edge.first, edge.second)) << "case " << cs << " diagonal on a face";
            } else {
                EXPECT_TRUE(share_face(edge.first, edge.second)) << "case " << cs;
                ++starts[edge.first];
                ++ends[edge.second];
            }
        }
        for (int e = 0; e < 12; ++e) {
            const int want = (kTables.edges[cs] >> e) & 1;
            EXPECT_EQ(starts[e], want) << "case " << cs << " edge " << e;
            EXPECT_EQ(ends[e], want) << "case " << cs << " edge " << e;
        }
    }
}

// With corner values ±1 and vertices at edge midpoints, each triangle's normal points towards
// increasing φ: positive dot product with the trilinear gradient at the triangle's centroid.
TEST(McTables, WindingFacesOutside) {
    for (int cs = 1; cs < 255; ++cs) {
        const auto& t = kTables.triangles[cs];
        for (int j = 0; t[j] != mc::kEnd; j += 3) {
            const Vec3d a = edge_mid(t[j]), b = edge_mid(t[j + 1]), c = edge_mid(t[j + 2]);
            const Vec3d n = cross(b - a, c - a);
            const Vec3d m = (a + b + c) / 3.0;
            Vec3d grad{};
            for (int k = 0; k < 8; ++k) {
                const double v = ((cs >> k) & 1) ? -1.0 : 1.0;
                const Vec3d o = corner_pos(k);
                for (int ax = 0; ax < 3; ++ax) {
                    double w = 1;
                    for (int o2 = 0; o2 < 3; ++o2) {
                        if (o2 == ax) continue;
                        w *= o[o2] ? m[o2] : 1 - m[o2];
                    }
                    grad[ax] += v * w * (o[ax] ? 1.0 : -1.0);
                }
            }
            EXPECT_GT(dot(n, grad), 0.0) << "case " << cs << " triangle " << j / 3;
        }
    }
}

}  // namespace
}  // namespace liveset
