// Build step: makes the default female and male bodies with the generator and writes their meshes
// to the file named on the command line (body/baked.hpp's format), which the build then compiles
// into drape_default_bodies. Generating them takes ~1.1 s each; done here, `drape dress` and every
// other use of a default body skips it.
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
    std::vector<drape::body::BakedBody> bodies;
    for (const drape::Sex sex : {drape::Sex::Female, drape::Sex::Male})
      bodies.push_back({sex, drape::generate_default_body(sex).mesh});
    const std::string bytes = drape::body::encode_baked_bodies(bodies);
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
