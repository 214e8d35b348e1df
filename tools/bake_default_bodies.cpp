// Build step: solves for the MakeHuman shapes of the default female and male bodies (the average
// adult of each sex) and writes them to the file named on the command line (body/baked.hpp's
// format), which the build then compiles into drape_default_bodies. The solve takes ~1 s a body;
// done here, `drape dress` and every other use of a default body only builds the body from it.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>

#include "body/baked.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT\n", argv[0]);
    return 2;
  }
  try {
    std::vector<drape::body::MhShape> shapes;
    for (const drape::Sex sex : {drape::Sex::Female, drape::Sex::Male})
      shapes.push_back(drape::body::solve_human_shape(sex, drape::default_body_request(sex)));
    const std::string bytes = drape::body::encode_baked_shapes(shapes);
    const std::filesystem::path out = argv[1];
    const std::filesystem::path tmp = out.string() + ".tmp";
    {
      std::ofstream file(tmp, std::ios::binary);
      file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      if (!file) throw std::runtime_error("cannot write " + tmp.string());
    }
    std::filesystem::rename(tmp, out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bake_default_bodies: %s\n", e.what());
    return 1;
  }
  return 0;
}
