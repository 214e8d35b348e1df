// The JSON API, endpoint by endpoint, with good and bad input: every answer has the right status
// and a message that says what is wrong (never a server path), and the server keeps serving.
#include <algorithm>
#include <fstream>
#include <sstream>

#include "drape/body.hpp"
#include "drape/error.hpp"
#include "drape/io.hpp"
#include "web/web_fixture.hpp"

namespace drape::test {
namespace {

using nlohmann::json;

std::string read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

httplib::Result upload(httplib::Client& c, const std::string& bytes, const std::string& filename,
                       const std::string& units = "m", const std::string& up = "y") {
  const httplib::MultipartFormDataItems items{
      {"file", bytes, filename, "application/octet-stream"}, {"units", units, "", ""}, {"up", up, "", ""}};
  return c.Post("/api/bodies", items);
}

httplib::Result post_json(httplib::Client& c, const std::string& path, const json& body) {
  return c.Post(path.c_str(), body.dump(), "application/json");
}

class WebApi : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ServeOptions o = quick_serve_options("web_api");
    o.max_upload_bytes = 8u << 20;
    server_ = new TestServer(o);
  }
  static void TearDownTestSuite() {
    delete server_;
    server_ = nullptr;
  }
  static TestServer* server_;
};
TestServer* WebApi::server_ = nullptr;

TEST_F(WebApi, HealthSaysOkAndDescribesTheQueue) {
  auto c = server_->client();
  const auto r = c.Get("/api/health");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  const json j = json_of(r);
  EXPECT_EQ(j["status"], "ok");
  EXPECT_EQ(j["workers"], 1);
  EXPECT_GE(j["queue"]["capacity"].get<int>(), 1);
}

TEST_F(WebApi, CatalogueListsBuiltinsWithSizesFabricAndThumbnail) {
  auto c = server_->client();
  const json j = json_of(c.Get("/api/garments"));
  ASSERT_TRUE(j.contains("garments"));
  bool shirt = false;
  for (const json& g : j["garments"]) {
    EXPECT_FALSE(g["sizes"].empty()) << g["name"];
    EXPECT_EQ(g["colour"].get<std::string>().size(), 7u);
    if (g["name"] != "shirt") continue;
    shirt = true;
    EXPECT_EQ(g["fabric"], "cotton");
    const auto png = c.Get(g["thumbnail"].get<std::string>());
    ASSERT_TRUE(png);
    EXPECT_EQ(png->status, 200);
    EXPECT_EQ(png->get_header_value("Content-Type"), "image/png");
    EXPECT_EQ(png->body.substr(1, 3), "PNG");
    EXPECT_GT(png->body.size(), 1000u);
  }
  EXPECT_TRUE(shirt);
  const auto missing = c.Get("/api/garments/no-such-garment/thumbnail.png");
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->status, 404);
  EXPECT_FALSE(error_of(missing).empty());
}

TEST(WebCatalogue, GarmentFilesOfTheCatalogueFolderAreOffered) {
  ServeOptions o = quick_serve_options("web_catalogue");
  o.catalogue_dir = temp_dir("web_catalogue_files");
  const std::filesystem::path assets = std::filesystem::path(DRAPE_SOURCE_DIR) / "assets" / "garments";
  std::filesystem::copy_file(assets / "skirt.json", o.catalogue_dir / "pencil-skirt.json");
  std::ofstream(o.catalogue_dir / "broken.json") << "{ not a garment";
  std::filesystem::copy_file(assets / "skirt.json", o.catalogue_dir / "Bad Name.json");
  TestServer server(o);
  auto c = server.client();
  const json list = json_of(c.Get("/api/garments"))["garments"];
  std::vector<std::string> names;
  for (const json& g : list) names.push_back(g["name"]);
  EXPECT_NE(std::find(names.begin(), names.end(), "pencil-skirt"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "shirt"), names.end());
  EXPECT_EQ(std::find(names.begin(), names.end(), "broken"), names.end());
  EXPECT_EQ(std::find(names.begin(), names.end(), "Bad Name"), names.end());
  const auto png = c.Get("/api/garments/pencil-skirt/thumbnail.png");
  ASSERT_TRUE(png);
  EXPECT_EQ(png->status, 200);
  EXPECT_EQ(png->body.substr(1, 3), "PNG");
  // A missing catalogue folder is an error the command reports.
  ServeOptions missing = quick_serve_options("web_catalogue_missing");
  missing.catalogue_dir = missing.data_dir / "no-such-folder";
  EXPECT_THROW(WebServer{missing}, InputError);
}

TEST_F(WebApi, BodyFromMeasurements) {
  auto c = server_->client();
  const auto r =
      post_json(c, "/api/bodies", {{"sex", "female"}, {"measurements", {{"height", 1.68}, {"bust", 0.9}}}});
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 201) << r->body;
  const json j = json_of(r);
  EXPECT_TRUE(is_hex_id(j["id"]));
  EXPECT_NEAR(j["height_m"].get<double>(), 1.68, 0.01);
  EXPECT_NEAR(j["measurements"]["bust"].get<double>(), 0.9, 0.01);
  // The body is reachable through its id, and its mesh is a GLB.
  const auto again = c.Get("/api/bodies/" + j["id"].get<std::string>());
  ASSERT_TRUE(again);
  EXPECT_EQ(again->status, 200);
  const auto glb = c.Get("/api/bodies/" + j["id"].get<std::string>() + "/body.glb");
  ASSERT_TRUE(glb);
  EXPECT_EQ(glb->status, 200);
  EXPECT_EQ(glb->body.substr(0, 4), "glTF");
}

TEST_F(WebApi, BadMeasurementsAreRefusedSayingWhy) {
  auto c = server_->client();
  const struct {
    std::string body;
    std::string says;
  } cases[] = {
      {"{not json", "JSON"},
      {"[1, 2]", "object"},
      {R"({"sex": "alien"})", "sex"},
      {R"({"measurements": {"height": "tall"}})", "height"},
      {R"({"measurements": {"wingspan": 1.7}})", "wingspan"},
      {R"({"measurements": {"height": 5.0}})", "height"},
      {R"({"measurements": [1.7]})", "measurements"},
      {R"({"measurements": {"underbust": 1.0, "bust": 0.8}})", "measurements"},
      {R"({"measurements": {"height=1.7,waist": 0.8}})", "height=1.7,waist"},
  };
  for (const auto& k : cases) {
    const auto r = c.Post("/api/bodies", k.body, "application/json");
    ASSERT_TRUE(r) << k.body;
    EXPECT_EQ(r->status, 400) << k.body;
    const std::string e = error_of(r);
    EXPECT_NE(e.find(k.says), std::string::npos) << k.body << " -> " << e;
    EXPECT_EQ(e.find("--"), std::string::npos) << "a command-line option in " << e;
  }
}

TEST_F(WebApi, BodiesAreBounded) {
  ServeOptions o = quick_serve_options("web_api_bodies");
  o.max_bodies = 2;
  TestServer small(o);
  auto c = small.client();
  EXPECT_EQ(c.Post("/api/bodies", "{}", "application/json")->status, 201);
  const std::string second = json_of(c.Post("/api/bodies", "{}", "application/json"))["id"];
  const auto full = c.Post("/api/bodies", "{}", "application/json");
  ASSERT_TRUE(full);
  EXPECT_EQ(full->status, 503);
  EXPECT_FALSE(full->get_header_value("Retry-After").empty());
  EXPECT_FALSE(error_of(full).empty());
  // A deleted body makes room.
  EXPECT_EQ(c.Delete("/api/bodies/" + second)->status, 204);
  EXPECT_EQ(c.Post("/api/bodies", "{}", "application/json")->status, 201);
}

TEST_F(WebApi, FindMySizeTriesEverySizeAndRecommendsOne) {
  auto c = server_->client();
  const std::string body = json_of(c.Post("/api/bodies", R"({"sex": "female"})", "application/json"))["id"];
  const auto r = c.Post("/api/tryons", json{{"body", body}, {"garment", "skirt"}, {"size", "auto"}}.dump(),
                        "application/json");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 202) << r->body;
  const json t = wait_for_tryon(c, json_of(r)["id"]);
  ASSERT_EQ(t["state"], "done") << t.dump();
  const json& advice = t["report"]["size_advice"];
  ASSERT_TRUE(advice.is_object()) << t["report"].dump();
  EXPECT_EQ(advice["sizes"].size(), 3u);  // the skirt's S, M and L
  EXPECT_FALSE(advice["reasons"].empty());
  // The size shown is the recommended one, or, where none closes and stays on, the chart's.
  const json recommended = advice["recommended_size"];
  if (recommended.is_string()) {
    EXPECT_EQ(t["size"], recommended);
  }
  EXPECT_TRUE(t["size"] == "S" || t["size"] == "M" || t["size"] == "L") << t["size"];
}

TEST_F(WebApi, UploadedBodyIsMeasured) {
  auto c = server_->client();
  const Body body = default_body(Sex::Female);
  // The same body in centimetres, Z up: converted on load as the fields say.
  Mesh cm = body.mesh;
  for (Vec3f& v : cm.positions) v = Vec3f(v.x(), -v.z(), v.y()) * 100.0f;
  const auto r = upload(c, encode_obj(cm), "scan.OBJ", "cm", "z");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 201) << r->body;
  EXPECT_NEAR(json_of(r)["height_m"].get<double>(), body.measurements.height, 0.01);
  const std::vector<unsigned char> ply = encode_ply(body.mesh);
  const auto p = upload(c, std::string(ply.begin(), ply.end()), "scan.ply");
  ASSERT_TRUE(p);
  EXPECT_EQ(p->status, 201) << p->body;
}

TEST_F(WebApi, BadUploadsAreRefusedSayingWhyWithoutServerPaths) {
  auto c = server_->client();
  const std::filesystem::path corpus = std::filesystem::path(DRAPE_SOURCE_DIR) / "tests" / "corpus" / "info";
  size_t tried = 0;
  for (const auto& f : std::filesystem::directory_iterator(corpus)) {
    const std::string ext = f.path().extension().string();
    if (ext != ".obj" && ext != ".ply" && ext != ".glb") continue;
    ++tried;
    const auto r = upload(c, read_bytes(f.path()), f.path().filename().string());
    ASSERT_TRUE(r) << f.path();
    EXPECT_EQ(r->status, 400) << f.path() << ": " << r->body;
    const std::string e = error_of(r);
    EXPECT_TRUE(e.starts_with("upload" + ext)) << f.path() << " -> " << e;
    EXPECT_EQ(e.find(corpus.string()), std::string::npos) << e;
    EXPECT_EQ(e.find(server_->options.data_dir.string()), std::string::npos) << e;
    EXPECT_EQ(e.find(f.path().filename().string()), std::string::npos) << e;
  }
  EXPECT_GT(tried, 30u);
  // A body in the wrong units is too small to be a person.
  const auto metres_as_mm = upload(c, encode_obj(default_body(Sex::Female).mesh), "body.obj", "mm");
  ASSERT_TRUE(metres_as_mm);
  EXPECT_EQ(metres_as_mm->status, 400);
  EXPECT_NE(error_of(metres_as_mm).find("height"), std::string::npos) << error_of(metres_as_mm);
  // Formats and fields the service does not take.
  const auto gltf = upload(c, "{}", "body.gltf");
  ASSERT_TRUE(gltf);
  EXPECT_EQ(gltf->status, 400);
  EXPECT_NE(error_of(gltf).find("OBJ, PLY or GLB"), std::string::npos);
  const auto units = upload(c, "v 0 0 0\n", "body.obj", "furlong");
  ASSERT_TRUE(units);
  EXPECT_EQ(units->status, 400);
  EXPECT_TRUE(error_of(units).starts_with("units")) << error_of(units);
  // A field that is not UTF-8 is quoted back with its bad bytes replaced (the answer is JSON), and
  // the server keeps serving.
  const auto not_utf8 = upload(c, "v 0 0 0\n", "body.obj", "furlong\xD5");
  ASSERT_TRUE(not_utf8);
  EXPECT_EQ(not_utf8->status, 400);
  EXPECT_TRUE(error_of(not_utf8).starts_with("units")) << error_of(not_utf8);
  const auto alive = c.Get("/api/health");
  ASSERT_TRUE(alive);
  EXPECT_EQ(alive->status, 200);
  const auto no_file = c.Post("/api/bodies", httplib::MultipartFormDataItems{{"units", "m", "", ""}});
  ASSERT_TRUE(no_file);
  EXPECT_EQ(no_file->status, 400);
  // A GLB naming a file on the server's disk for its buffer is refused before anything is read.
  const std::string gltf_json =
      R"({"asset":{"version":"2.0"},"buffers":[{"uri":"/etc/hostname","byteLength":4}]})";
  std::string glb = "glTF";
  const auto u32 = [&](uint32_t v) {
    for (int i = 0; i < 4; ++i) glb.push_back(static_cast<char>((v >> (8 * i)) & 255u));
  };
  u32(2);
  u32(static_cast<uint32_t>(20 + gltf_json.size()));
  u32(static_cast<uint32_t>(gltf_json.size()));
  u32(0x4E4F534Au);
  glb += gltf_json;
  const auto external = upload(c, glb, "body.glb");
  ASSERT_TRUE(external);
  EXPECT_EQ(external->status, 400);
  EXPECT_NE(error_of(external).find("external file"), std::string::npos) << error_of(external);
  // Still serving.
  const auto health = c.Get("/api/health");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
}

TEST_F(WebApi, OversizeUploadsAre413) {
  auto c = server_->client();
  const auto big = upload(c, std::string(9u << 20, '#'), "big.obj");
  ASSERT_TRUE(big) << "the server closed the connection instead of answering 413";
  EXPECT_EQ(big->status, 413);
  EXPECT_FALSE(error_of(big).empty());
  // Too many triangles, though few bytes: a server with a small triangle limit.
  ServeOptions o = quick_serve_options("web_api_triangles");
  o.max_upload_triangles = 1000;
  TestServer small(o);
  auto s = small.client();
  const auto many = upload(s, encode_obj(default_body(Sex::Female).mesh), "body.obj");
  ASSERT_TRUE(many);
  EXPECT_EQ(many->status, 413);
  EXPECT_NE(error_of(many).find("triangles"), std::string::npos) << error_of(many);
  const auto health = c.Get("/api/health");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
}

TEST_F(WebApi, BadTryOnsAndUnknownIds) {
  auto c = server_->client();
  const std::string body = json_of(post_json(c, "/api/bodies", {{"sex", "male"}}))["id"];
  const std::string unknown(32, 'a');
  const struct {
    std::string request;
    int status;
    std::string says;
  } cases[] = {
      {"{oops", 400, "JSON"},
      {json{{"body", body}, {"size", "M"}}.dump(), 400, "garment"},
      {json{{"body", body}, {"garment", 7}, {"size", "M"}}.dump(), 400, "garment"},
      {json{{"body", body}, {"garment", "cape"}, {"size", "M"}}.dump(), 400, "cape"},
      {json{{"body", body}, {"garment", "shirt"}, {"size", "XXXXL"}}.dump(), 400, "size"},
      {json{{"body", unknown}, {"garment", "shirt"}, {"size", "M"}}.dump(), 404, "body"},
      {json{{"body", "../../etc/passwd"}, {"garment", "shirt"}, {"size", "M"}}.dump(), 404, "body"},
  };
  for (const auto& k : cases) {
    const auto r = c.Post("/api/tryons", k.request, "application/json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, k.status) << k.request;
    EXPECT_NE(error_of(r).find(k.says), std::string::npos) << k.request << " -> " << error_of(r);
  }
  for (const std::string& path :
       {"/api/tryons/" + unknown, std::string("/api/tryons/NOT-AN-ID"),
        "/api/tryons/" + unknown + "/dressed.glb", "/api/bodies/" + unknown,
        "/api/bodies/" + unknown + "/body.glb", "/api/bodies/" + body + "/secret.txt",
        std::string("/api/bodies/..%2F..%2Fetc/body.glb"), std::string("/api/nothing-here")}) {
    const auto r = c.Get(path);
    ASSERT_TRUE(r) << path;
    EXPECT_EQ(r->status, 404) << path;
    EXPECT_FALSE(error_of(r).empty()) << path;
  }
  const auto del = c.Delete("/api/bodies/" + unknown);
  ASSERT_TRUE(del);
  EXPECT_EQ(del->status, 404);
}

TEST_F(WebApi, TryOnIsDressedCachedAndDeleted) {
  auto c = server_->client();
  const std::string body = json_of(post_json(c, "/api/bodies", {{"sex", "female"}}))["id"];
  const json request{{"body", body}, {"garment", "skirt"}, {"size", "M"}};
  const auto r = post_json(c, "/api/tryons", request);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 202) << r->body;
  const std::string id = json_of(r)["id"];
  EXPECT_TRUE(is_hex_id(id));
  // Progress only grows, from queued through running to done.
  double last = 0;
  json t;
  for (int i = 0; i < 20000; ++i) {
    t = json_of(c.Get("/api/tryons/" + id));
    ASSERT_TRUE(t.is_object());
    const double p = t["progress"];
    EXPECT_GE(p, last);
    EXPECT_LE(p, 1.0);
    last = p;
    if (t["state"] == "done" || t["state"] == "failed") break;
    EXPECT_TRUE(t["state"] == "queued" || t["state"] == "running") << t.dump();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(t["state"], "done") << t.dump();
  EXPECT_EQ(t["progress"], 1.0);
  EXPECT_EQ(t["size"], "M");
  EXPECT_TRUE(t["report"]["quality"].contains("max_strain"));
  EXPECT_TRUE(t["report"]["fit"].contains("garments"));
  const auto dressed = c.Get("/api/tryons/" + id + "/dressed.glb");
  ASSERT_TRUE(dressed);
  EXPECT_EQ(dressed->status, 200);
  EXPECT_EQ(dressed->body.substr(0, 4), "glTF");
  const auto fit = c.Get("/api/tryons/" + id + "/fit.glb");
  ASSERT_TRUE(fit);
  EXPECT_EQ(fit->body.substr(0, 4), "glTF");
  const auto preview = c.Get("/api/tryons/" + id + "/preview.png");
  ASSERT_TRUE(preview);
  EXPECT_EQ(preview->body.substr(1, 3), "PNG");
  // The same request again is answered from the cache, without a new dressing.
  const auto again = post_json(c, "/api/tryons", request);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->status, 200);
  EXPECT_EQ(json_of(again)["id"], id);
  EXPECT_TRUE(json_of(again)["cached"].get<bool>());
  // Deleted: the body, the try-on and their files answer 404.
  const auto del = c.Delete("/api/bodies/" + body);
  ASSERT_TRUE(del);
  EXPECT_EQ(del->status, 204);
  for (const std::string& path : {"/api/bodies/" + body, "/api/bodies/" + body + "/body.glb",
                                  "/api/tryons/" + id, "/api/tryons/" + id + "/dressed.glb"}) {
    const auto gone = c.Get(path);
    ASSERT_TRUE(gone);
    EXPECT_EQ(gone->status, 404) << path;
  }
  const auto twice = c.Delete("/api/bodies/" + body);
  ASSERT_TRUE(twice);
  EXPECT_EQ(twice->status, 404);
}

}  // namespace
}  // namespace drape::test
