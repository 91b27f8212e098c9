// Charting for the UV atlas: a partition of the faces into charts that are topological disks
// (connected, one boundary loop, no pinched vertex), grown from seeds under a normal cone.
//
// Growth (greedy, one chart at a time): from a seed face, faces are taken in order of centroid
// distance from the seed (Dijkstra over face adjacency, so charts come out round) while their
// normal stays within `max_normal_angle_degrees` of the chart's area-weighted mean normal and the
// chart stays a disk. The disk test is local: a face joins a disk chart and keeps it a disk
// exactly when it shares one chart edge and its third vertex is not yet in the chart, or shares two
// chart edges and its third edge has no chart face on its other side (Euler characteristic 1 and
// one boundary loop are kept; sharing three edges would close a sphere, and a third vertex already
// in the chart would make a handle or a pinch). A face is also refused when it would leave a vertex
// on the chart's border with more than 0.95·2π of the chart's face angles around it: such a border
// vertex (a saddle) cannot be laid out flat without overlap by a conformal map. Charts under
// `min_chart_faces` are then dissolved and their faces offered to their neighbours under a wider
// cone; what is left is grown again.
#ifndef SFT_ATLAS_CHARTS_H_
#define SFT_ATLAS_CHARTS_H_

#include <string>
#include <vector>

#include "src/atlas/mesh_topology.h"

namespace sft {

struct ChartingOptions {
  // Largest angle between a face's normal and its chart's mean normal; degrees, (0, 90].
  double max_normal_angle_degrees = 60.0;
  // Charts with fewer faces are dissolved into their neighbours (where the disk test allows);
  // [1, 1000]. 1 keeps every chart.
  int min_chart_faces = 16;
  // Largest chart; faces, 0 = no limit. Used when a chart is split.
  int max_chart_faces = 0;

  bool Check(std::string* why) const;
};

// Assigns a chart to every face f of `subset` (every non-degenerate face when `subset` is empty):
// (*chart_of_face)[f] = a new id ≥ *num_charts, which is advanced past the ids used. Faces outside
// the subset must already hold a chart id other than -1; degenerate faces are left at -1.
// `chart_of_face` has one entry per face.
void GrowCharts(const MeshTopology& topology, const std::vector<int>& subset,
                const ChartingOptions& options, std::vector<int>* chart_of_face, int* num_charts);

// Splits the chart made of `faces` (a disk) in two: charts grow at once from the two faces
// farthest apart (the face farthest from the chart's mean centroid, then the face farthest from
// that one), each face going to the chart that reaches it first by centroid distance and takes it
// (disk and border-angle tests; no normal cone). Faces neither chart can take become charts of
// their own (GrowCharts with `options`). New ids start at *num_charts, as in GrowCharts.
void SplitChart(const MeshTopology& topology, const std::vector<int>& faces,
                const ChartingOptions& options, std::vector<int>* chart_of_face, int* num_charts);

// Whether face f may join chart c with the chart staying a disk (the test above).
bool KeepsDisk(const MeshTopology& topology, const std::vector<int>& chart_of_face, int f, int c);
// Whether face f may join chart c without a border vertex's angle sum passing 0.95·2π (above).
bool KeepsBorderAnglesFlat(const MeshTopology& topology, const std::vector<int>& chart_of_face,
                           int f, int c);

}  // namespace sft

#endif  // SFT_ATLAS_CHARTS_H_
