// Labels every point of a cloud as non-edge, sharp edge or boundary with glint's BoundED model
// and writes the labelled cloud (scalar_label, scalar_p_sharp, scalar_p_boundary, colours).
//   classify_cloud INPUT OUTPUT.ply [MODEL.json]
#include <cstdio>

#include "core/error.h"
#include "edges/classifier.h"
#include "edges/model.h"
#include "io/ply.h"
#include "io/point_cloud_io.h"

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: %s INPUT OUTPUT.ply [MODEL.json]\n", argv[0]);
    return 2;
  }
  try {
    glint::PointCloud cloud = glint::io::read_point_cloud(argv[1]);
    const glint::edges::Model model =
        glint::edges::Model::load(argc == 4 ? argv[3] : DEFAULT_MODEL);
    const glint::edges::Classification result = glint::edges::classify(cloud, model);
    glint::edges::attach_classification(cloud, result);
    glint::io::write_ply(argv[2], cloud);

    std::size_t counts[3] = {0, 0, 0};
    for (const auto label : result.labels) ++counts[label < 3 ? label : 2];
    std::printf("%zu points: %zu non-edge, %zu sharp, %zu boundary -> %s\n", cloud.size(),
                counts[0], counts[1], counts[2], argv[2]);
  } catch (const glint::Error& e) {
    std::fprintf(stderr, "classify_cloud: %s\n", e.what());
    return 1;
  }
  return 0;
}
