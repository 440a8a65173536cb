#pragma once
/// @file One pass of the implicit untangling over fixed fields (Buffet et al. 2019; Gong et
/// al. 2023, sections 3-4): projection steps that move every free vertex toward the zero set
/// of its layer's field composed with the others' (untangled fields), edges sampled so that a
/// long chord sees the layers it passes near, and shape matching toward each piece's rest
/// shape. run_engine() builds one per pass, after the fields are brought up to date.

#include "untangle/detail/engine.h"

#include "strata/core/types.h"
#include "strata/field/field.h"
#include "strata/geometry/scene.h"
#include "strata/untangle/localize.h"
#include "strata/untangle/untangle.h"

#include <memory>
#include <vector>

namespace strata::detail {

/// One pass of projection + shape matching over the fields of a work scene, which stay
/// fixed while it runs. Every argument of the constructor must outlive the pass.
class ProjectionPass {
  public:
    /// `min_separation`: the gap aimed for at least between constrained layers (scene units);
    /// `sample_spacing`: the spacing of the samples on the edges (scene units; 0: only
    /// params.edge_samples a edge). EngineSettings holds both.
    ProjectionPass(const Scene& work, const RelationSource& relations, const SceneFields& fields,
                   const UntangleParams& params, double min_separation, double sample_spacing);
    ~ProjectionPass();
    ProjectionPass(const ProjectionPass&) = delete;
    ProjectionPass& operator=(const ProjectionPass&) = delete;

    /// EngineSettings::keep_simple: no move that makes a self-crossing.
    void set_keep_simple(bool on);
    /// EngineSettings::ends_by_nearest: an open layer is left out past one of its ends only
    /// where its nearest feature is that end.
    void set_ends_by_nearest(bool on);

    /// One projection step of every free vertex of `pieces` (Jacobi: every vertex and edge
    /// reads the positions at the start of the step; the result does not depend on the number
    /// of threads). Returns the summed displacement length (scene units).
    double project(Scene& scene, const std::vector<Piece>& pieces);

    /// Shape matching of every piece toward its rest shape (`rest`, one per piece, in order).
    void match_shapes(Scene& scene, const std::vector<Piece>& pieces,
                      const std::vector<std::vector<Vec2>>& rest);

    /// The largest |fhat - f| over the samples of the last project() (scene units).
    double max_violation() const;

    /// UntangleParams::give_up_when_stalled's threshold: the smallest slack, over the
    /// constrained pairs of work layers, between the gap aimed for and the gap the final check
    /// accepts (separation_tolerance x required); +inf where a constrained pair needs less
    /// than min_separation.
    double slack() const;

  private:
    class Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace strata::detail
