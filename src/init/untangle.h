// Local repair of a surface that passes through itself in a few places, without a topology
// change: the vertices around the self-intersecting faces are smoothed towards the mean of their
// neighbours (umbrella Laplacian, Taubin 1995's first step) until no face intersects another or
// the rounds run out. For the small tangles a gradient step leaves in thin parts (claws, teeth,
// creases); a surface that crosses itself broadly needs resampling (resample.h) instead.
#ifndef SFT_INIT_UNTANGLE_H_
#define SFT_INIT_UNTANGLE_H_

#include <string>

#include "src/core/status.h"
#include "src/geometry/mesh.h"

namespace sft {

struct UntangleOptions {
  int max_rounds = 8;    // smoothing rounds, each followed by a recount, [1, 100].
  int ring = 2;          // vertices within this many edges of a tangled face move, [0, 8].
  int smooth_steps = 2;  // umbrella steps per round, [1, 50].
  double step = 0.5;     // fraction of the way to the neighbours' mean per step, (0, 1].

  bool Check(std::string* why) const;
};

struct UntangleReport {
  int faces_before = 0;    // self-intersecting faces before the repair.
  int faces_after = 0;     // and after it (0 = repaired; never more than before).
  int rounds = 0;          // smoothing rounds run.
  int moved_vertices = 0;  // distinct vertices moved up to the round kept.
};

// Repairs `mesh` in place (vertex positions only; faces and their order are kept). The result is
// the round with the fewest self-intersecting faces; when no round has fewer than the input, the
// input is kept unchanged (faces_after == faces_before, moved_vertices 0). Errors: the
// options are invalid, or the intersecting faces cannot be named (SelfIntersectingFaces false: no
// faces, a CGAL failure, degenerate or repeated faces). A mesh without self-intersections is
// returned unchanged.
Status Untangle(const UntangleOptions& options, TriMesh* mesh, UntangleReport* report);

}  // namespace sft

#endif  // SFT_INIT_UNTANGLE_H_
