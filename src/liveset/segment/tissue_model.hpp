// Tissue intensity model: a mixture of tissue classes (for a T1 brain CSF, grey and white matter)
// fitted to the intensity histogram of a region, with partial-volume classes between neighbouring
// tissues, and the threshold window it gives the seeds' class.
//
// Model (raw intensity units). K pure classes k = 0..K-1, sorted by mean, each a Gaussian
// N(µ_k, σ_k²) with weight w_k; between neighbours k and k+1 a partial-volume class with weight v_k
// whose voxels hold a fraction f ~ U(0, 1) of tissue k+1: N((1−f)µ_k + fµ_{k+1}, (1−f)σ_k² + fσ_{k+1}²)
// (Santago & Gage 1993; FSL FAST's partial-volume model). Without the mixed classes, voxels on
// tissue borders widen and shift the pure classes, and a plain Gaussian mixture's decision
// boundaries drift toward the narrower class. Fitted by EM on a histogram (the mixed classes' shapes
// follow the pure classes' parameters) from two starts: multi-level Otsu thresholds (a plain
// mixture first, then the mixed classes) and the histogram's most prominent peaks (the mixed
// classes at once); the peak start's fit is kept where it is sound, each class a peak of its own and
// no spike, and it is more likely by over 0.001 nats per voxel or Otsu's fit is not sound.
//
// Window rule. The seeds pick their class (the pure class most of their voxels are most probably
// in). The window reaches from the midpoint with the darker neighbour to the midpoint with the
// brighter one: (µ_{k−1} + µ_k)/2 … (µ_k + µ_{k+1})/2. A voxel on the border between two tissues
// holds a mix of both and its intensity is the fraction-weighted mean; the crisp truth assigns it
// to the tissue with the larger fraction, so the border lies where the intensity equals the
// midpoint of the two class means. The threshold term D is 0 exactly at µ ± ε, so the front settles
// on that iso-intensity surface. The rule uses only the class means: it does not depend on the
// classes' spreads or weights (noise, amount of partial volume, the brain's proportions), which
// are what change between scanners and subjects. A class at either end of the intensity range
// has one neighbour: its outer edge is placed symmetrically, at least 3σ_k beyond its mean.
// µ is the window's centre and ε its half width.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "liveset/grid/grid.hpp"

namespace liveset {

struct TissueModelOptions {
    int classes = 3;            // pure tissue classes, [2, 6] (T1 brain: CSF, GM, WM)
    int bins = 512;             // histogram bins between the low and high quantiles, [32, 65536]
    double low_quantile = 0.001;   // voxels outside these quantiles of the region are left out
    double high_quantile = 0.999;
    bool partial_volume = true;    // mixed classes between neighbouring tissues
    int max_iterations = 2000;
    double tolerance = 1e-8;       // stop when the mean log-likelihood per voxel changes less
    void validate() const;         // std::invalid_argument with a one-line message
};

struct TissueClass {
    double mean = 0.0;    // raw units
    double sigma = 0.0;
    double weight = 0.0;  // share of the region's voxels in this pure class
    // The spread the histogram's own peak shows for this class: its wider side's half width at
    // half maximum as a Gaussian σ (the histogram smoothed, that smoothing taken out); infinite
    // when the class has no peak of its own (the smoothed histogram's maximum within mean ± sigma
    // lies on that range's edge or nearer another class's mean, or a side never falls to half). On a sound fit the two agree to
    // about a quarter (the peak's wider side a little wider: partial volume); a fit much wider than
    // its peak took voxels the peak does not hold: a neighbour pinned to one value (an
    // intensity-normalised T1, FreeSurfer's white matter at 110) leaves its partial-volume voxels to it.
    double peak_sigma = std::numeric_limits<double>::infinity();
    // What the noise ratio (alpha.hpp) reads: sigma up to 1.3 × peak_sigma, peak_sigma from 1.8 ×,
    // a linear blend between (no jump in α as an image changes a little).
    double spread() const {
        if (!(sigma > 1.3 * peak_sigma)) return sigma;
        const double t = (sigma / peak_sigma - 1.3) / 0.5;
        return t >= 1.0 ? peak_sigma : sigma - t * (sigma - peak_sigma);
    }
};

// The order of a brain's tissues by intensity, as the automatic brain mask reads it off the deep
// head or a brain (brain_mask.hpp; docs/ARCHITECTURE.md): a T1, CSF < GM < WM; grey matter brighter
// than white (a T2, a PD), WM < GM < CSF. (A FLAIR, CSF < WM < GM, reads as a T1: its GM and WM
// classes are then named the wrong way round; docs/BENCHMARKS.md, session 64.)
enum class TissueContrast { kT1, kGreyBrighter };
// "T1", "grey brighter than white (T2, PD)".
const char* to_string(TissueContrast contrast);

struct TissueModel {
    std::vector<TissueClass> classes;  // sorted by mean
    std::vector<double> mixed;         // weight of the partial-volume class between k and k+1
    std::size_t voxels = 0;            // voxels fitted
    int iterations = 0;
    bool converged = false;
    double log_likelihood = 0.0;       // mean per voxel at the end
    // Why the model cannot be used (classes that merged, collapsed or lost all weight); empty
    // when it is sound.
    std::string degenerate;
    std::string note;  // e.g. the partial-volume fit failed and the plain mixture is used
    // Where the EM started: "otsu" (multi-level Otsu's classes) or "peaks" (the histogram's most
    // prominent peaks; see above). `iterations` counts Otsu's plain and mixed runs, the peaks' mixed run.
    std::string start = "otsu";
    // σ (mm) of the Gaussian blur (smoothing.hpp) of the image the model was fitted on: 0 for the
    // image itself (fit_window_model, window.hpp, may fit the blurred image when noise hides a class).
    double smooth_mm = 0.0;
    // The region's contrast (brain_contrast, brain_mask.hpp; set by fit_window_model, window.hpp, for
    // a whole brain or an image known to be grey brighter); nullopt otherwise (not read: a T1
    // assumed). It names three classes (tissue_class_name).
    std::optional<TissueContrast> contrast;
    // Where grey matter is brighter than white in the region (fit_window_model): the region's
    // voxels at or below this value, darker than white matter (not brain), were left out of the fit.
    std::optional<double> floor;

    bool usable() const { return degenerate.empty(); }
    // Index of the pure class with the largest posterior at `value` (mixed classes ignored).
    int classify(double value) const;
    // Mixture density at `value` (pure and mixed classes).
    double density(double value) const;
};

// Fits the model to the values of `image` inside `region` (non-zero voxels; the whole image when
// null). Throws std::invalid_argument for bad options, a region of other dimensions or without
// voxels, non-finite voxels, or too few distinct intensities for the classes asked for. A model
// that fits but is unusable comes back with `degenerate` set.
TissueModel fit_tissue_model(const Grid<float>& image, const Grid<std::uint8_t>* region,
                             const TissueModelOptions& options = {});
// The same on a sample of values (the histogram is built from them).
TissueModel fit_tissue_model(std::span<const float> values, const TissueModelOptions& options = {});

struct ModelWindow {
    int seed_class = -1;
    double seed_class_share = 0.0;  // share of the seed voxels classified into seed_class
    double lower = 0.0, upper = 0.0;  // raw units; mu = (lower + upper)/2, epsilon = (upper − lower)/2
    double mu() const { return 0.5 * (lower + upper); }
    double epsilon() const { return 0.5 * (upper - lower); }
    std::vector<std::string> warnings;  // one line each (seeds in two classes, ...)
};

// The window for the seeds' class (see the rule above) from the raw intensities of the seed
// voxels. Throws std::invalid_argument when the model is not usable or there are no seed values.
ModelWindow model_window(const TissueModel& model, std::span<const float> seed_values);

// Multi-level Otsu on a histogram (bin counts and the bins' intensities): the first bin of each
// class after the first (k − 1 indices, ascending), maximising the between-class variance.
// Throws std::invalid_argument with fewer bins than classes.
std::vector<std::size_t> otsu_split_bins(std::span<const double> counts, std::span<const double> centres, int classes);

// Multi-level Otsu thresholds (raw units, ascending) splitting `values` into `classes` classes on a
// histogram of `bins` bins between their 0.1 and 99.9 % quantiles.
std::vector<double> otsu_thresholds(std::span<const float> values, int classes, int bins = 256);

// The tissue names of a model of 3 classes from dark to bright by its contrast (a T1 where not read):
// CSF, GM, WM, or WM, GM, CSF (grey brighter). "class 1".."class K" for other class counts.
std::string tissue_class_name(const TissueModel& model, int k);

}  // namespace liveset
