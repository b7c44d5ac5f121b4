// Generates a small sphere with the installed library, simplifies it and checks the
// result is a non-empty, smaller mesh.
#include <cstdio>

#include "oocsimp/generate.hpp"
#include "oocsimp/simplify.hpp"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  std::string path = std::string(argv[1]) + "/consumer-sphere.ply";
  oocsimp::GenerateOptions g;
  g.triangles = 20000;
  oocsimp::generate_mesh(path, g);
  oocsimp::MeshInput in = oocsimp::open_mesh_input(path);
  oocsimp::SimplifyOptions o;
  o.sizing.grid = 16;
  oocsimp::SimplifyStats st;
  oocsimp::SimplifiedMesh m = oocsimp::simplify(in, o, &st);
  std::printf("%llu -> %llu triangles\n", (unsigned long long)st.input_triangles,
              (unsigned long long)st.output_triangles);
  return (st.output_triangles > 0 && st.output_triangles < st.input_triangles &&
          m.triangles.size() == 3 * st.output_triangles)
             ? 0
             : 1;
}
