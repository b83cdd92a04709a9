// The README example, built against an installed batchcol through find_package(batchcol CONFIG).
#include <batchcol/batchcol.hpp>
#include <cstdio>

int main() {
  using namespace batchcol;
  ShapeTable shapes;                                   // each shape stored once, pairs refer to indices
  const auto box = shapes.add(Shape::box(0.1, 0.2, 0.3));
  const auto pill = shapes.add(Shape::capsule(0.05, 0.2).inflated(0.01));
  PairBatch batch;                                     // structure of arrays
  for (int i = 0; i < 1000; ++i)
    batch.add(box, Pose::identity(), pill, Pose{{0.3 + 0.001 * i, 0, 0}, Eigen::Quaterniond(1, 0, 0, 0)});
  QueryOptions options;
  options.level = QueryLevel::penetration;             // boolean < distance < witness < penetration
  options.tolerance = 1e-10;                           // metres, certified by the duality gap
  PairResults results;
  collide(shapes, batch, options, results);            // all cores; same bits for any thread count
  std::printf("pair 0: %s, distance %.6f, normal %.3f %.3f %.3f\n", to_string(results.status[0]),
              results.distance[0], results.normal.x[0], results.normal.y[0], results.normal.z[0]);
}
