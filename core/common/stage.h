// The pipeline's stages: what --stats times (stage_seconds) and what progress names. One
// enumeration so that a stage has one name everywhere (the add-on weighs progress by these
// names: blender/meshquilt/engine.py).
#pragma once

#include <cstdint>

namespace mq {

enum class Stage : std::uint8_t {
  Prepare,              // inputs checked, base cleaned and refined, swatch prepared
  MethodChoice,         // --method auto: which layout suits the swatch
  Symmetry,             // the swatch's lattice and symmetries (global layout)
  Parameterization,     // local patches' maps (3.1) or the global layout's
  Tiling,               // the global layout's lattice or thread pieces
  Placement,            // the global layout's elements onto the base
  UnfitLayout,          // a global layout tried and refused (--method auto)
  Streamlines,          // vines: stems grown along the field
  Stems,                // vines: stems as swatch vines
  Leaves,               // vines: leaves along the stems
  Quilting,             // the planar steps over the whole run (section 2)
  Matching,             // section 2.4
  Correspondence,       // section 2.5
  Deformation,          // section 2.6
  Merging,              // section 2.7
  PostProcessing,       // the synthesised elements collected
  ShellMap,             // section 3.2: offset surface, tetrahedra, atlas
  StretchOptimization,  // section 3.2, Eq. (9)
  Embedding,            // local coordinates to 3D
  PlacementCheck,       // signed heights over the base (issue 23)
  FoldRepair,           // folded elements unfolded (issue 13)
  RingSeparation,       // touching rings moved apart
  ElementRemoval,       // what still intersects removed
  Coverage,             // the share of the base covered
  Structure,            // the structure measure (links, shapes)
  Animation,            // --swatch-frames: the output located in the swatch, frames settled
  SaveQuilt,            // --save-quilt
  Writing,              // the output files
};

// The stage's name in --stats and progress lines (lower case, words apart), in the order of
// the enumeration.
constexpr const char* kStageNames[] = {
    "prepare",               // Prepare
    "method choice",         // MethodChoice
    "symmetry",              // Symmetry
    "parameterization",      // Parameterization
    "tiling",                // Tiling
    "placement",             // Placement
    "unfit layout",          // UnfitLayout
    "streamlines",           // Streamlines
    "stems",                 // Stems
    "leaves",                // Leaves
    "quilting",              // Quilting
    "matching",              // Matching
    "correspondence",        // Correspondence
    "deformation",           // Deformation
    "merging",               // Merging
    "post-processing",       // PostProcessing
    "shell map",             // ShellMap
    "stretch optimization",  // StretchOptimization
    "embedding",             // Embedding
    "placement check",       // PlacementCheck
    "fold repair",           // FoldRepair
    "ring separation",       // RingSeparation
    "element removal",       // ElementRemoval
    "coverage",              // Coverage
    "structure",             // Structure
    "animation",             // Animation
    "save quilt",            // SaveQuilt
    "writing",               // Writing
};
static_assert(sizeof(kStageNames) / sizeof(kStageNames[0]) == static_cast<int>(Stage::Writing) + 1);

constexpr const char* stage_name(Stage stage) { return kStageNames[static_cast<int>(stage)]; }

}  // namespace mq
