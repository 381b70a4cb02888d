// A coarse level of detail of a fragment-meshed surface, for drawing while the user interacts:
// marching cubes of φ sampled at every k-th lattice point per axis (about 1/k² of the triangles),
// in fragments of S coarse cells (k x k x k fine fragments of S cells: fewer draw calls, which
// llvmpipe pays for), kept up to date incrementally from the fine fragments the fine mesher
// rebuilt (U).
//
// Coarse point c is fine point k·c; the coarse lattice has k times the spacing, the same origin and
// direction, so a coarse vertex v lies at fine index k·v. Standard library + oneTBB only.
#pragma once

#include <span>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/mesh/fragment_mesher.hpp"

namespace liveset {

class LodMesher {
public:
    // `fine` the full-resolution lattice, `factor` k (2 to 8); the coarse fragments hold
    // fine_fragment_size cells per edge. Throws std::invalid_argument on fine_fragment_size < 1,
    // a factor outside [2, 8] or an empty lattice.
    LodMesher(const Lattice& fine, int fine_fragment_size, int factor = 2);
    int factor() const { return factor_; }

    const Lattice& lattice() const { return coarse_phi_.lattice(); }  // coarse lattice
    const FragmentMesher& mesher() const { return mesher_; }
    const Grid<float>& phi() const { return coarse_phi_; }  // φ at the fine points k·c

    // Samples all of `phi` and re-meshes every coarse fragment.
    void rebuild(const Grid<float>& phi);
    // After the fine mesher rebuilt fragments `fine_ids` (every changed φ point is a corner of a
    // cell of one of them): re-samples their point boxes and re-meshes the affected coarse
    // fragments, whose ids it returns (sorted). `phi` has the fine lattice's dimensions.
    std::vector<FragmentId> update(const Grid<float>& phi, const FragmentMesher& fine, std::span<const FragmentId> fine_ids);
    // The same without the fine mesher (its meshing deferred, e.g. during a background run):
    // re-samples every coarse point (1 / k³ of φ) and re-meshes the coarse fragments whose samples
    // changed, whose ids it returns (sorted).
    std::vector<FragmentId> refresh(const Grid<float>& phi);

private:
    std::vector<FragmentId> rebuild_all(const Grid<float>& phi);  // rebuild(); every id

    int factor_ = 2;
    Grid<float> coarse_phi_;
    FragmentMesher mesher_;
    bool built_ = false;
};

// The coarse lattice of LodMesher: ceil(dims / k) points, spacing x k, same origin and direction.
Lattice coarsened(const Lattice& fine, int factor);

}  // namespace liveset
