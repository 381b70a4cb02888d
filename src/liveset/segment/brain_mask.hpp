// Automatic brain mask from a T1-weighted image (full head or already skull-stripped), so a
// segmentation of a full-head scan cannot leak into scalp, muscle, eyes or neck. In the spirit of
// morphological brain-extraction tools: head threshold, brain-tissue window from the histogram,
// erosion to cut the thin bridges, largest component, regrowth, hole filling, closing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "liveset/grid/grid.hpp"
#include "liveset/segment/tissue_model.hpp"

namespace liveset {

// Radii are in millimetres (the lattice spacing), so 2 mm scans and anisotropic voxels behave.
// The defaults are meant to work untuned on adult human T1 scans.
struct BrainMaskOptions {
    // Background threshold: p2 + fraction·(p98 − p2) of the intensities (FSL BET's robust 10 %):
    // inside the head, what lies below it is background (skull, air, dark CSF).
    double background_fraction = 0.1;
    // The head threshold, which separates the head from the air around it, is the background
    // threshold or, when the air's histogram shows a noise mode σ above its floor (a noisy
    // magnitude image: Rayleigh, 13.5 % of it above 2σ, too sparse to connect 6-neighbours),
    // floor + noise_multiple·σ if higher, so heavy noise does not make the whole field of view
    // "head". The mode counts only with noise_min_share of the voxels within 2σ of the floor (air,
    // not a cropped scan's dark tissue). 0: no such raise.
    double noise_multiple = 2.0;
    double noise_min_share = 0.05;
    // A voxel is brain tissue when the image blurred by a Gaussian of this σ (mm; gaussian_smooth,
    // smoothing.hpp) lies in the tissue window (the window itself comes from the image as it is), so
    // noise does not punch the cortex out of the mask: BrainWeb + noise σ 12, 86.7 % → 99.6 % of GM
    // inside. 0: no blur.
    double smoothing_mm = 1.0;
    // Erosion of the brain-tissue mask that cuts the bridges (optic nerves, vessels, partial volume)
    // to scalp, muscle and eyes before the largest component is taken.
    double erosion_mm = 4.0;
    // The core grows back by erosion_mm + regrow_margin_mm, but only into brain-tissue voxels.
    double regrow_margin_mm = 1.0;
    // Closing that takes in the sulcal CSF and the cortex's outer partial-volume layer.
    double closing_mm = 6.0;
    // Final growth into voxels brighter than the background threshold (extracerebral CSF, dark cortex).
    double rim_mm = 2.0;
    // Grey matter brighter than white (T2, PD): the CSF around the brain, brighter than the tissue
    // window, is taken in where it joins the brain within this distance (mm) of it (not in a
    // skull-stripped input, whose mask is its foreground). 0: not.
    double csf_reach_mm = 5.0;
    // Closing of the head foreground that bridges the dark skull, giving a solid head whose surface
    // the skull-stripping test measures from.
    double head_closing_mm = 5.0;
    // Only the head within this distance (mm) of its top along the world's superior axis (LPS +z)
    // holds the brain: below it lie neck and shoulders, whose deep muscle would otherwise be read
    // as the deep head's white matter (FSL's robustfov keeps 170 mm from the top of the head too).
    // The depth is still measured from the whole head's surface. 0: the whole head.
    double brain_extent_mm = 170.0;
    // ... but only where a neck leaves the field of view: the head's cross-section in the array's
    // most inferior face is at least this (mm²; a neck's is ~100 cm²). A head that ends inside the
    // image has nothing to cut.
    double neck_exit_mm2 = 1000.0;
    // ... and a tilted head (pitched or rolled in the field of view) reaches further below its top:
    // where the brain found meets the cut over more than this (mm²; an upright brain's brainstem
    // ~10 cm², BrainWeb rolled 5° 39 cm², pitched back 20° 64 cm²), the brain is extracted again
    // from the head cut 15 mm lower (up to 60 mm), with the tissue window the first look found.
    // 0: never.
    double cut_contact_mm2 = 2000.0;
    // A child's head is smaller: within an adult's 170 mm lies its neck, whose muscle outweighs its
    // white matter ("no brain found"; BrainWeb scaled by 0.7 with 90 mm of neck). Where no brain is
    // found within brain_extent_mm, it is looked for once more within brain_extent_mm × the head's
    // size over an adult's (its widest cross-section within 0.65 × brain_extent_mm of its top, as a
    // disc's diameter, over adult_head_mm; BrainWeb's 195-197 mm at any voxel size), at least 0.6 of it. A head where the
    // first look succeeds is never cut shorter.
    double adult_head_mm = 190.0;
    // Whether the header says which way is superior. False for a header without orientation (an
    // Analyze file, a NIfTI with neither qform nor sform, read as identity: its z may be the
    // anterior axis of a coronal stack, and the cut would take 30 mm of frontal lobe): the face the
    // head leaves the field of view through most (the neck) is then taken as inferior.
    bool superior_from_header = true;
    // Skull-stripped input: at least `stripped_fraction` of the mask's boundary lies within
    // `stripped_near_mm` of the head's surface (a full head has scalp and skull in between). The
    // mask is then the filled non-background foreground. Set detect_skull_stripped false to skip.
    // Measured: full heads 0-0.02, skull-stripped brains and phantoms 0.73-0.90, a defaced head (the
    // face cut off to 3 mm in front of the frontal lobe, as pydeface-like tools do) 0.09-0.12.
    bool detect_skull_stripped = true;
    // A full head's brain fills a large part of it (BrainWeb: 46 %); a mask under this share of
    // the solid head is not a brain (e.g. a noisy scan without skull whose core shrank to a
    // fragment) and is refused as "no brain found" (NoBrainFound: the default ROI then segments the
    // whole image, and says so).
    double min_head_share = 0.1;
    // A last look where every other found no brain: where over this share of the deep head lies 3 σ
    // above its tallest peak, and the deep head is skewed dark as a T1's, that peak is not white
    // matter's but what swamps it (a T1's CSF in ventricles of about 270 ml, BrainWeb's grown by
    // 210 ml; the neck's muscle where the cut is not made; docs/BENCHMARKS.md session 70), and white
    // matter's is taken at the brightest prominent peak above it. A T1's deep head holds ≤ 5.6 %
    // there, a FLAIR's 23 %, vent8's 63–66 %. 1: never.
    double swamped_share = 0.4;
    double stripped_near_mm = 4.0;
    double stripped_fraction = 0.4;
};

// Throws std::invalid_argument naming the first bad field.
void validate(const BrainMaskOptions& options);

// What the method found.
struct BrainMaskReport {
    double background_threshold = 0;  // background threshold (image units)
    double background_noise = 0;      // the air's noise σ (its mode above the floor) when found, else 0
    double head_threshold = 0;        // head threshold: background, raised above the air's noise
    double wm_peak = 0;               // white-matter peak of the deep head's histogram
    double wm_sigma = 0;              // its width (upper half-width at half maximum / 1.1774)
    double wm_low_sigma = 0;          // the same on its lower side
    // The deep head's voxels above the background: their quantile skew (q90 + q10 − 2·q50)/(q90 − q10),
    // negative where grey matter and CSF lie below white matter (a T1), positive above (a T2, a PD),
    // and their shares over and under the white-matter peak by 3 σ (its narrower side's).
    double deep_skew = 0;
    double deep_above = 0, deep_below = 0;
    // White matter was taken at the deep head's brightest prominent peak, its tallest swamped
    // (BrainMaskOptions::swamped_share: the last look).
    bool wm_swamped = false;
    // Skewed bright (deep_skew > 0) with two peaks standing out in the deep head's histogram: the
    // brighter, grey matter's, and its width (upper half-width, to its valley with CSF at most); the
    // darker is then the white-matter peak. NaN otherwise.
    double deep_grey_peak = std::numeric_limits<double>::quiet_NaN();
    double deep_grey_sigma = 0;
    // Read as a T1 and yet a prominent peak above the white-matter peak with at least 10 % of the deep
    // head 3 σ above it: grey matter brighter than white with CSF dark (a FLAIR; session 68), its peak
    // and width (NaN otherwise). Where the T1 window's mask reaches the head's surface, the window is
    // mirrored from it and kept if that mask does not (flair true); `contrast` stays a T1's, as the
    // tissue model reads a FLAIR (CSF, white and grey matter from dark up).
    double flair_grey_peak = std::numeric_limits<double>::quiet_NaN();
    double flair_grey_sigma = 0;
    bool flair = false;
    // The contrast read off the deep head (deep_contrast, brain_histogram.hpp) as the tissue window
    // was taken: a T1's, or mirrored for grey matter brighter than white (T2, PD; one that finds no
    // grey-matter peak for it falls back to a T1's).
    TissueContrast contrast = TissueContrast::kT1;
    double tissue_low = 0;            // brain-tissue window (image units)
    double tissue_high = 0;
    std::size_t head_voxels = 0;      // solid head (filled, closed foreground) within brain_extent_mm of its top
    std::size_t below_voxels = 0;     // solid head further below its top (neck, shoulders), left out
    double inferior_exit_mm2 = 0;     // the solid head's cross-section in the array's most inferior face (mm²)
    double brain_extent_mm = 0;       // the extent below the top the brain was looked for in (0: the whole head)
    double cut_contact_mm2 = 0;       // the brain's cross-section at the first cut (0: no cut); over the
                                      // option's, the brain was looked for lower (a tilted head), and
                                      // brain_extent_mm is where the last look kept cut
    double head_diameter_mm = 0;      // the head's size (adult_head_mm), where a neck is cut (else 0)
    bool superior_from_header = true; // the options': up was the header's superior axis, else found from the head
    std::size_t tissue_voxels = 0;    // head voxels in the tissue window
    std::size_t core_voxels = 0;      // largest component after the erosion
    double surface_contact = 0;       // fraction of the mask boundary near the head surface
    bool skull_stripped = false;      // the input looked skull-stripped (mask = filled foreground)
    // A masked outside's value where it lies within the tissue's range (a skull-stripped brain
    // z-scored inside its mask, the outside left at 0): the exact value of most of the array's
    // faces, filling ≥ 2 % of the image, with ≥ 5 % of the rest darker. Its voxels connected to the faces are
    // read as lying below every other (the mask is then found as for a skull-stripped image).
    // NaN when there is none.
    double mid_range_fill = std::numeric_limits<double>::quiet_NaN();
    std::size_t csf_voxels = 0;       // the bright CSF taken in around a grey-brighter brain (csf_reach_mm)
    std::size_t mask_voxels = 0;
    double mask_volume_mm3 = 0;
};

// The head a brain mask was found in: the solid head (the closed, filled foreground above the head
// threshold, neck included) and each voxel's depth in it (mm). A smooth multiplicative correction of
// the intensities (N4) does not move the head's surface against the dark air around it, so the brain
// can be found again on the corrected image inside the same head (prepare_image, apps/common).
// A masked outside within the tissue's range (BrainMaskReport::mid_range_fill) is kept with it: N4's
// correction about a floor (bias_correction.offset) makes it uneven, and it is still the outside.
struct BrainMaskHead {
    Grid<std::uint8_t> solid;
    Grid<float> depth;
    Grid<std::uint8_t> outside;  // empty when the image was not so masked
    double outside_value = std::numeric_limits<double>::quiet_NaN();
};

// What auto_brain_mask throws where it found a head but no brain in it (a mask under
// min_head_share of the head, or none left after the erosion, in every look; a head of one value
// throughout is a plain std::invalid_argument, as no head): the default ROI then tells the user
// it gave up (BrainLookup::no_brain, apps/common), where an image with no head at all is no head's.
struct NoBrainFound : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

// The brain mask (0/1) on the image's lattice. Deterministic for any thread count.
// `head` (optional, in and out): when it holds a head of the image's size, the brain is looked for
// in that head (the head step is skipped; every threshold is still read off this image); when it is
// empty, it receives the head found here.
// Throws std::invalid_argument with a one-line message on bad options, an empty image, non-finite
// voxels, a constant image, an image with no head (no solid foreground: e.g. pure noise), a given
// head of another size; NoBrainFound (one) when a head is found but no brain in it.
Grid<std::uint8_t> auto_brain_mask(const Grid<float>& image, const BrainMaskOptions& options = {},
                                   BrainMaskReport* report = nullptr, BrainMaskHead* head = nullptr);

// A region's contrast, by the rule auto_brain_mask reads the deep head with (deep_contrast,
// brain_histogram.hpp) on the deep half of `brain` (by depth inside it), for a brain mask from any
// source (a region without air: no background test); its non-finite voxels are left out. A T1 for an
// empty region or one of a single value. It may differ from BrainMaskReport::contrast of the same
// brain, which also tests the background and falls back to a T1's window without a grey-matter peak.
// `tissue_floor` (optional) receives, for a brain whose grey matter is brighter than its white, the
// white-matter peak less 3 σ of its darker side: white matter is such a brain's darkest tissue, so
// what lies below is not brain (the skull, dura and air a mask takes in); −∞ otherwise.
// `known_grey_brighter`: the brain was read so on the image before N4 (PreparedImage, apps/common):
// it is read so here too, and the floor taken below the white-matter peak found here. (N4 fitted in
// such a brain takes part of its grey-white contrast for a field, grey matter lying outside white
// matter; a low-contrast PD then reads as a T1. N4 cannot give a T1 that contrast.)
// Throws std::invalid_argument for a region of another size than the image.
TissueContrast brain_contrast(const Grid<float>& image, const Grid<std::uint8_t>& brain, double* tissue_floor = nullptr,
                              bool known_grey_brighter = false);

}  // namespace liveset
