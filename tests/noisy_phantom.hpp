// A noisy phantom on 1 × 1 × 1.5 mm voxels: an image on which the automatic curvature weight
// (segment/alpha.hpp) is neither 0 nor 0.1, for the tests that compare the Session's α with segment's.
#pragma once

#include "liveset/phantom/phantom.hpp"

namespace liveset::testing {

struct NoisyAnisotropicPhantom {
    Phantom phantom;    // its seeds and truth (index space, as the image's)
    Grid<float> image;  // the phantom's intensities on 1 × 1 × 1.5 mm voxels
};

inline NoisyAnisotropicPhantom noisy_anisotropic_phantom(int size) {
    PhantomOptions po;
    po.size = size;
    po.noise = 0.12;
    NoisyAnisotropicPhantom out{make_phantom(po), Grid<float>()};
    const Lattice& l = out.phantom.image.lattice();
    out.image = Grid<float>(Lattice(l.dims(), {1.0, 1.0, 1.5}, l.origin(), l.direction()));
    for (PointIndex i = 0; i < out.image.size(); ++i) out.image[i] = out.phantom.image[i];
    return out;
}

}  // namespace liveset::testing
