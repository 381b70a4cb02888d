// FragmentMesher: union of fragments equals whole-lattice marching cubes for several fragment
// sizes, incremental updates after random local edits equal a fresh rebuild fragment by fragment,
// U holds exactly the fragments reached by the edit (corners + normal stencil), thread-count
// invariance and surface-proportional work for a single whole-lattice fragment.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include <tbb/global_control.h>

#include "liveset/mesh/fragment_mesher.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "levelset/levelset_test_util.hpp"
#include "liveset/levelset/shapes.hpp"
#include "mesh/mesh_test_fields.hpp"

namespace liveset {
namespace {

using testing::random_field;
using testing::sphere_field;

bool same_vertices(std::span<const Vertex> a, std::span<const Vertex> b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        for (int k = 0; k < 3; ++k)
            if (a[i].position[k] != b[i].position[k] || a[i].normal[k] != b[i].normal[k]) return false;
    return true;
}

bool same_fragment(const FragmentView& a, const FragmentView& b) {
    return same_vertices(a.vertices, b.vertices) &&
           std::equal(a.indices.begin(), a.indices.end(), b.indices.begin(), b.indices.end());
}

void expect_same_meshers(const FragmentMesher& a, const FragmentMesher& b) {
    ASSERT_EQ(a.fragment_count(), b.fragment_count());
    for (FragmentId f = 0; f < a.fragment_count(); ++f)
        ASSERT_TRUE(same_fragment(a.fragment(f), b.fragment(f))) << "fragment " << f;
}

// Brute-force set of fragments that own a cell with a corner at x or at a 6-neighbour of x.
std::set<FragmentId> brute_affected(const FragmentMesher& m, std::span<const PointIndex> xs) {
    const Lattice& l = m.lattice();
    std::set<FragmentId> out;
    const Vec3i d = l.dims();
    for (PointIndex x : xs) {
        const Vec3i p = l.coord(x);
        for (int z = std::max(p.z - 2, 0); z <= std::min(p.z + 1, d.z - 2); ++z)
            for (int y = std::max(p.y - 2, 0); y <= std::min(p.y + 1, d.y - 2); ++y)
                for (int xx = std::max(p.x - 2, 0); xx <= std::min(p.x + 1, d.x - 2); ++xx) {
                    bool reads = false;  // some corner of cell (xx,y,z) within Manhattan distance 1 of p
                    for (int c = 0; c < 8; ++c) {
                        const Vec3i q{xx + (c & 1), y + ((c >> 1) & 1), z + ((c >> 2) & 1)};
                        const Vec3i dd = q - p;
                        if (std::abs(dd.x) + std::abs(dd.y) + std::abs(dd.z) <= 1) reads = true;
                    }
                    if (reads) out.insert(m.fragment_of_cell({xx, y, z}));
                }
    }
    return out;
}

TEST(FragmentMesher, LayoutOwnsEveryCellOnce) {
    const FragmentMesher m(Lattice(Vec3i{12, 9, 7}), 4);  // cells 11x8x6 -> fragments 3x2x2
    EXPECT_EQ(m.fragment_dims(), (Vec3i{3, 2, 2}));
    std::size_t cells = 0;
    for (FragmentId f = 0; f < m.fragment_count(); ++f) {
        const FragmentView v = m.fragment(f);
        EXPECT_EQ(m.fragment_id(m.fragment_coord(f)), f);
        cells += std::size_t(v.cell_extent.x) * v.cell_extent.y * v.cell_extent.z;
    }
    EXPECT_EQ(cells, 11u * 8u * 6u);
    EXPECT_EQ(m.fragment(2).cell_extent, (Vec3i{3, 4, 4}));
    EXPECT_THROW(FragmentMesher(Lattice(Vec3i{4, 4, 4}), 0), std::invalid_argument);
}

TEST(FragmentMesher, UnionOfFragmentsEqualsWholeLattice) {
    std::vector<Grid<float>> fields;
    fields.push_back(sphere_field({40, 37, 41}, {19.7, 18.2, 20.4}, 14));
    fields.push_back(random_field({18, 17, 19}, 7, false));
    for (const Grid<float>& phi : fields) {
        const Mesh whole = marching_cubes_naive(phi);
        const auto want = canonical_triangles(whole);
        const std::vector<PointIndex> zero = zero_crossing_points(phi);
        for (int s : {3, 5, 7, 16, 1000}) {
            FragmentMesher scan(phi.lattice(), s), band(phi.lattice(), s);
            scan.full_rebuild(phi);
            band.full_rebuild(phi, zero);
            expect_same_meshers(scan, band);
            // Every triangle exactly once (no duplicates at fragment borders).
            EXPECT_EQ(scan.triangle_count(), whole.triangle_count()) << "S=" << s;
            const Mesh merged = scan.merged();
            EXPECT_EQ(canonical_triangles(merged), want) << "S=" << s;
            // Welded union is the same surface as the whole-lattice mesh.
            const Mesh w = weld_vertices(merged, 1e-5);
            EXPECT_EQ(w.vertices.size(), whole.vertices.size()) << "S=" << s;
            EXPECT_EQ(edge_stats(w).nonmanifold_edges, 0u);
            if (s == 1000) {
                EXPECT_EQ(scan.vertex_count(), whole.vertices.size());
            } else {
                EXPECT_GT(scan.vertex_count(), whole.vertices.size());  // border vertices per fragment
            }
            for (FragmentId f = 0; f < scan.fragment_count(); ++f) {
                const FragmentView v = scan.fragment(f);
                for (std::uint32_t i : v.indices) ASSERT_LT(i, v.vertices.size());
            }
        }
    }
}

// Random local edits: after every incremental update each fragment's V/T is bit-identical to a
// fresh full rebuild, the union equals whole-lattice marching cubes, U equals the brute-force set
// and fragments outside U are untouched. A twin mesher told the sign changes (with some extra
// points that did not flip) gives the same U and fragments.
void run_incremental(int fragment_size, std::uint32_t seed, int edits) {
    Grid<float> phi = sphere_field({26, 24, 25}, {12.6, 11.4, 12.2}, 8);
    FragmentMesher m(phi.lattice(), fragment_size);
    m.full_rebuild(phi);
    FragmentMesher told(phi.lattice(), fragment_size);
    told.full_rebuild(phi);
    std::mt19937 rng(seed);
    const Vec3i d = phi.dims();
    for (int e = 0; e < edits; ++e) {
        // Change φ at 1..4 points within a small neighbourhood of a random point.
        std::uniform_int_distribution<int> ux(0, d.x - 1), uy(0, d.y - 1), uz(0, d.z - 1), un(1, 4), off(-1, 1);
        std::uniform_real_distribution<float> val(-1.5f, 1.5f);
        const Vec3i centre{ux(rng), uy(rng), uz(rng)};
        std::vector<PointIndex> changed;
        const Grid<float> old = phi;
        const int n = un(rng);
        for (int i = 0; i < n; ++i) {
            Vec3i p = centre + Vec3i{off(rng), off(rng), off(rng)};
            if (!phi.lattice().contains(p)) continue;
            phi(p) = (i == 0 && e % 7 == 0) ? 0.0f : val(rng);
            changed.push_back(phi.lattice().index(p));
        }
        if (!changed.empty() && e % 5 == 0) changed.push_back(changed.front());  // duplicates allowed
        // Snapshot fragments to verify untouched ones do not change.
        std::vector<Mesh> before(m.fragment_count());
        for (FragmentId f = 0; f < m.fragment_count(); ++f) {
            const FragmentView v = m.fragment(f);
            before[f].vertices.assign(v.vertices.begin(), v.vertices.end());
            before[f].indices.assign(v.indices.begin(), v.indices.end());
        }
        const std::vector<FragmentId> predicted = m.affected_fragments(changed);
        const std::vector<FragmentId> u = m.update(phi, changed);
        std::vector<PointIndex> flips;
        for (PointIndex x : changed)
            if (is_inside(old[x]) != is_inside(phi[x]) || (e % 3 == 0 && flips.empty())) flips.push_back(x);
        ASSERT_EQ(told.update(phi, changed, flips), u) << "edit " << e;
        expect_same_meshers(told, m);
        ASSERT_TRUE(std::is_sorted(u.begin(), u.end()));
        ASSERT_EQ(u, predicted);
        const std::set<FragmentId> brute = brute_affected(m, changed);
        ASSERT_EQ(std::set<FragmentId>(u.begin(), u.end()), brute) << "edit " << e;
        for (FragmentId f = 0; f < m.fragment_count(); ++f) {
            if (brute.count(f)) continue;
            ASSERT_TRUE(same_vertices(m.fragment(f).vertices, before[f].vertices));
            ASSERT_TRUE(std::ranges::equal(m.fragment(f).indices, before[f].indices));
        }
        FragmentMesher fresh(phi.lattice(), fragment_size);
        fresh.full_rebuild(phi);
        expect_same_meshers(m, fresh);
        if (e % 10 == 0) {
            ASSERT_EQ(canonical_triangles(m.merged()), canonical_triangles(marching_cubes_naive(phi))) << "edit " << e;
        }
    }
}

TEST(FragmentMesher, IncrementalEditsMatchFullRebuild) {
    run_incremental(1, 10, 100);  // sizes 1 and 2: a stencil spans up to four fragments per axis
    run_incremental(2, 15, 100);
    run_incremental(3, 11, 300);
    run_incremental(5, 12, 200);
    run_incremental(7, 13, 200);
    run_incremental(1000, 14, 150);
}

// The level set's own X: the incremental step with sleeping stretches of front (growth, stall,
// flicker, plus local edits) fed to update() gives, after every step, the fragments of a rebuild.
TEST(FragmentMesher, IncrementalStepsWithSleepingFrontMatchFullRebuild) {
    SparseField f(Lattice({36, 34, 32}), 2);
    f.init_from_sdf(shapes::Sphere({17.5, 16.5, 15.5}, 4.0));
    const testing::BlobSpeed speed({17.5, 16.5, 15.5}, 11.0);
    StepOptions options;
    options.mode = StepMode::kIncremental;
    options.sleep_after = 8;
    FragmentMesher m(f.lattice(), 5), told(f.lattice(), 5);  // told: given the level set's sign changes
    m.full_rebuild(f.phi());
    told.full_rebuild(f.phi());
    std::mt19937 rng(77);
    std::size_t slept = 0;
    for (int s = 1; s <= 160; ++s) {
        const StepResult r = f.step(speed, options);
        slept += r.zero_layer - r.awake;
        m.update(f.phi(), r.changed.points);
        ASSERT_TRUE(r.changed.sign_changes.has_value());
        told.update(f.phi(), r.changed.points, *r.changed.sign_changes);
        if (s % 23 == 0) {
            const ChangedPoints x = f.apply_edits(testing::random_edit(f, rng));
            m.update(f.phi(), x.points);
            told.update(f.phi(), x.points, *x.sign_changes);
        }
        FragmentMesher fresh(f.lattice(), 5);
        fresh.full_rebuild(f.phi());
        expect_same_meshers(m, fresh);
        expect_same_meshers(told, fresh);
        if (::testing::Test::HasFatalFailure()) FAIL() << "step " << s;
    }
    EXPECT_GT(slept, 10000u);  // the steps did let stretches of front sleep
}

TEST(FragmentMesher, FarFragmentsAreNotRebuilt) {
    const Grid<float> phi = sphere_field({34, 34, 34}, {16.3, 16.6, 16.1}, 12);
    FragmentMesher m(phi.lattice(), 3);
    m.full_rebuild(phi);
    const Vec3i p{20, 17, 16};
    const std::vector<PointIndex> x{phi.lattice().index(p)};
    const std::vector<FragmentId> u = m.update(phi, x);
    // Cells with a corner at p: x 19..20, y 16..17, z 15..16 -> fragment (6,5,5). The normal
    // stencil adds cells with a corner at p±e: x up to 21 -> (7,5,5); y up to 18 -> (6,6,5);
    // z down to 14 -> (6,5,4). Nothing else of the 11^3 fragments.
    std::vector<FragmentId> want{m.fragment_id({6, 5, 5}), m.fragment_id({7, 5, 5}), m.fragment_id({6, 6, 5}),
                                 m.fragment_id({6, 5, 4})};
    std::sort(want.begin(), want.end());
    EXPECT_EQ(u, want);
    EXPECT_EQ(m.last_stats().fragments_rebuilt, 4u);
}

TEST(FragmentMesher, NormalStencilNeighboursAreIncluded) {
    // A point whose cells all lie in fragment 0 but which is a 6-neighbour of a corner of fragment 1.
    Grid<float> phi = sphere_field({20, 8, 8}, {6.2, 3.6, 3.3}, 5);  // surface crosses x = 9..11
    FragmentMesher m(phi.lattice(), 10);                           // cells x 0..9 | 10..18
    m.full_rebuild(phi);
    const Vec3i p{9, 3, 3};  // corner of cells x = 8, 9 (fragment 0); 6-neighbour (10,3,3) is in fragment 1
    phi(p) += 0.3f;
    const std::vector<PointIndex> x{phi.lattice().index(p)};
    const std::vector<FragmentId> u = m.update(phi, x);
    EXPECT_EQ(u, (std::vector<FragmentId>{0, 1}));
    FragmentMesher fresh(phi.lattice(), 10);
    fresh.full_rebuild(phi);
    expect_same_meshers(m, fresh);
}

TEST(FragmentMesher, ResultsIndependentOfThreadCount) {
    const Grid<float> phi = random_field({30, 28, 26}, 5, false);
    std::vector<FragmentMesher> runs;
    for (int threads : {1, 2, 4}) {
        tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
        FragmentMesher m(phi.lattice(), 4);
        m.full_rebuild(phi);
        runs.push_back(std::move(m));
    }
    expect_same_meshers(runs[0], runs[1]);
    expect_same_meshers(runs[0], runs[2]);
}

TEST(FragmentMesher, IncrementalUpdatesIndependentOfThreadCount) {
    // The X pass flags fragments and queues sign-flip rows from several threads; the result must not
    // depend on how many.
    std::vector<FragmentMesher> runs;
    for (int threads : {1, 2}) {
        tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
        SparseField f(Lattice({36, 34, 32}), 2);
        f.init_from_sdf(shapes::Sphere({17.5, 16.5, 15.5}, 4.0));
        const testing::BlobSpeed speed({17.5, 16.5, 15.5}, 11.0);
        FragmentMesher m(f.lattice(), 4);
        m.full_rebuild(f.phi(), f.zero_layer());
        for (int s = 1; s <= 60; ++s) m.update(f.phi(), f.step(speed, StepOptions{}).changed.points);
        runs.push_back(std::move(m));
    }
    ASSERT_GT(runs[0].triangle_count(), 0u);
    expect_same_meshers(runs[0], runs[1]);
}

TEST(FragmentMesher, SingleFragmentUpdateIsSurfaceProportional) {
    Grid<float> phi = sphere_field({64, 64, 64}, {31.7, 32.2, 31.4}, 20);
    FragmentMesher m(phi.lattice(), 64);
    ASSERT_EQ(m.fragment_count(), 1u);
    m.full_rebuild(phi);
    EXPECT_EQ(m.last_stats().cells_visited, 63u * 63u * 63u);
    const std::size_t crossing = marching_cubes_naive(phi).triangle_count();
    // Brute force: the cell rows (y, z) holding a crossing cell, and the crossing cells.
    const auto crossing_rows = [](const Grid<float>& g, std::size_t* cells) {
        std::set<std::pair<int, int>> rows;
        *cells = 0;
        for (int z = 0; z < 63; ++z)
            for (int y = 0; y < 63; ++y)
                for (int xx = 0; xx < 63; ++xx) {
                    const int cs = cell_case(g, {xx, y, z});
                    if (cs == 0 || cs == 255) continue;
                    rows.insert({y, z});
                    ++*cells;
                }
        return rows;
    };
    std::size_t cells_before = 0, cells_after = 0;
    std::set<std::pair<int, int>> rows = crossing_rows(phi, &cells_before);
    const Vec3i p{52, 32, 31};
    ASSERT_FALSE(is_inside(phi(p)));
    phi(p) = -0.7f;  // flips: the 4 cell rows around p become candidates too
    for (int z = p.z - 1; z <= p.z; ++z)
        for (int y = p.y - 1; y <= p.y; ++y) rows.insert({y, z});
    crossing_rows(phi, &cells_after);
    const std::vector<PointIndex> x{phi.lattice().index(p)};
    EXPECT_EQ(m.update(phi, x), (std::vector<FragmentId>{0}));
    // Visits the old crossing rows plus those around the flipped point (a third of the 3969 rows)
    // and polygonises exactly the crossing cells: far fewer than the 250k cells.
    EXPECT_EQ(m.last_stats().rows_visited, rows.size());
    EXPECT_LT(m.last_stats().rows_visited, 63u * 63u / 2);
    EXPECT_EQ(m.last_stats().cells_visited, cells_after);
    EXPECT_LT(m.last_stats().cells_visited, crossing);
    EXPECT_EQ(canonical_triangles(m.merged()), canonical_triangles(marching_cubes_naive(phi)));
}

// Brute force: the fragments owning a cell with a corner at p (those whose triangles a sign flip
// at p can change).
std::set<FragmentId> brute_reshaped(const FragmentMesher& m, Vec3i p) {
    std::set<FragmentId> out;
    const Vec3i d = m.lattice().dims();
    for (int z = std::max(p.z - 1, 0); z <= std::min(p.z, d.z - 2); ++z)
        for (int y = std::max(p.y - 1, 0); y <= std::min(p.y, d.y - 2); ++y)
            for (int x = std::max(p.x - 1, 0); x <= std::min(p.x, d.x - 2); ++x) out.insert(m.fragment_of_cell({x, y, z}));
    return out;
}

// A fragment whose cells' corner signs did not change keeps T and only recomputes V; one with a
// flipped corner is re-polygonised. Either way the result is bit for bit a fresh mesher's.
TEST(FragmentMesher, FragmentsWithoutASignFlipRefreshOnlyTheirVertices) {
    Grid<float> phi = sphere_field({30, 28, 26}, {14.6, 13.4, 12.7}, 9);
    FragmentMesher m(phi.lattice(), 6);
    m.full_rebuild(phi);  // a scan keeps no vertex edges: the next rebuild of each fragment is a row pass
    std::vector<PointIndex> all(phi.lattice().size());
    for (PointIndex i = 0; i < all.size(); ++i) all[i] = i;
    const auto scale = [&](float k) {  // moves every vertex (not where t is clamped), flips no sign
        for (float& v : phi.values()) v = v > 0.0f ? v * k : v / k;
    };
    const auto expect_fresh = [&] {
        FragmentMesher fresh(phi.lattice(), 6);
        fresh.full_rebuild(phi);
        expect_same_meshers(m, fresh);
    };
    const std::vector<Vertex> first(m.fragment(m.fragment_of_cell({14, 13, 3})).vertices.begin(),
                                    m.fragment(m.fragment_of_cell({14, 13, 3})).vertices.end());
    scale(1.3f);
    ASSERT_EQ(m.update(phi, all).size(), m.fragment_count());
    EXPECT_EQ(m.last_stats().vertices_only, 0u);  // after the scan: row passes
    expect_fresh();
    std::vector<std::uint64_t> stamps(m.fragment_count());
    for (FragmentId f = 0; f < m.fragment_count(); ++f) stamps[f] = m.fragment(f).topology;
    scale(0.8f);
    ASSERT_EQ(m.update(phi, all).size(), m.fragment_count());
    for (FragmentId f = 0; f < m.fragment_count(); ++f) ASSERT_EQ(m.fragment(f).topology, stamps[f]) << "T kept, stamp kept";
    EXPECT_EQ(m.last_stats().vertices_only, m.fragment_count());
    EXPECT_EQ(m.last_stats().cells_visited, 0u);
    EXPECT_EQ(m.last_stats().rows_visited, 0u);
    expect_fresh();
    EXPECT_FALSE(same_vertices(m.fragment(m.fragment_of_cell({14, 13, 3})).vertices, first));  // they did move

    // A flip at p re-polygonises exactly the fragments owning a cell with corner p; the other
    // affected fragments refresh their vertices.
    // p: next to the surface, on a fragment border in x (cells of two fragments), one point above
    // one in z (the normal stencil reaches the fragments below, whose signs did not change).
    Vec3i p{-1, -1, -1};
    for (int z = 7; z < 26 && p.x < 0; z += 6)
        for (int y = 1; y < 28 && p.x < 0; ++y)
            for (int x = 6; x < 30 && p.x < 0; x += 6)
                if (y % 6 >= 2 && std::abs(phi({x, y, z})) < 0.8f && phi({x, y, z}) != 0.0f) p = {x, y, z};
    ASSERT_GE(p.x, 0);
    phi(p) = -phi(p);
    const std::vector<PointIndex> x{phi.lattice().index(p)};
    const std::vector<FragmentId> u = m.update(phi, x);
    const std::set<FragmentId> reshaped = brute_reshaped(m, p);
    for (FragmentId f = 0; f < m.fragment_count(); ++f)
        EXPECT_EQ(m.fragment(f).topology != stamps[f], reshaped.count(f) == 1) << "fragment " << f;
    EXPECT_EQ(m.last_stats().fragments_rebuilt, u.size());
    EXPECT_EQ(m.last_stats().vertices_only, u.size() - reshaped.size());
    EXPECT_EQ(reshaped.size(), 2u);
    EXPECT_EQ(u.size(), 4u);
    expect_fresh();
    EXPECT_EQ(canonical_triangles(m.merged()), canonical_triangles(marching_cubes_naive(phi)));

    // A full rebuild from a zero layer (a new φ, as when a session loads one) polygonises every
    // fragment anew; it may not refresh vertices on the old triangles.
    phi = sphere_field({30, 28, 26}, {13.2, 14.1, 12.9}, 7);
    m.full_rebuild(phi, all);
    EXPECT_EQ(m.last_stats().vertices_only, 0u);
    expect_fresh();
}

TEST(FragmentMesher, RejectsMismatchedGridAndBadIndices) {
    FragmentMesher m(Lattice(Vec3i{8, 8, 8}), 3);
    const Grid<float> wrong = random_field({8, 8, 9}, 1, false);
    EXPECT_THROW(m.full_rebuild(wrong), std::invalid_argument);
    const Grid<float> phi = random_field({8, 8, 8}, 1, false);
    const std::vector<PointIndex> bad{512};
    EXPECT_THROW(m.update(phi, bad), std::out_of_range);
    const std::vector<PointIndex> good{511};
    EXPECT_THROW(m.update(phi, good, bad), std::out_of_range);
}

}  // namespace
}  // namespace liveset
