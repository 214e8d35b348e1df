// The HTTP side of the try-on (docs/web.md): routes of the JSON API over TryOnService, the page and
// its three.js, and the translation of every error into a status and {"error": "..."}.
#include <fmt/format.h>

#include <atomic>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>

#include "drape/error.hpp"
#include "drape/web.hpp"
#include "web/bodies.hpp"
#include "web/catalogue.hpp"
#include "web/http.hpp"
#include "web/ids.hpp"
#include "web/request_error.hpp"
#include "web/requests.hpp"
#include "web/service.hpp"

namespace drape {
namespace {

using nlohmann::json;

void send_json(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(body.dump(), "application/json");
}

void send_error(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  res.set_content(web::error_answer(message), "application/json");
}

// A finished file of a body or try-on, read whole (a few MB at most) so that a DELETE meanwhile
// cannot cut the answer short.
bool send_file(httplib::Response& res, const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream bytes;
  bytes << in.rdbuf();
  const std::string ext = path.extension().string();
  const char* type = ext == ".glb" ? "model/gltf-binary" : ext == ".png" ? "image/png" : "application/json";
  res.set_content(bytes.str(), type);
  // Shoppers' bodies: private, not kept by shared caches.
  res.set_header("Cache-Control", "private, no-store");
  return true;
}

// The standard words for statuses no route answered itself (unknown path, body too large, ...).
std::string status_message(int status) {
  switch (status) {
    case 400:
      return "the request is malformed";
    case 404:
      return "not found";
    case 405:
      return "that method is not allowed here";
    case 413:
      return "the upload is too large";
    case 414:
      return "the address is too long";
    case 415:
      return "unsupported content type";
    default:
      return status >= 500 ? "the server could not answer; please try again" : "the request was refused";
  }
}

json body_json(const web::BodyView& b) {
  return json{{"id", b.id}, {"measurements", b.measurements}, {"height_m", b.height_m}};
}

json tryon_json(const web::TryOnView& t) {
  json out{{"id", t.id},
           {"body", t.body},
           {"garment", t.garment},
           {"size_requested", t.size_requested},
           {"state", web::to_string(t.state)},
           {"progress", t.progress},
           {"size", t.size.empty() ? json(nullptr) : json(t.size)},
           {"report", t.report.is_null() ? json(nullptr) : t.report}};
  if (t.state == web::TryOnState::Failed) out["error"] = t.error;
  if (t.state == web::TryOnState::Done) {
    const std::string base = "/api/tryons/" + t.id + "/";
    out["files"] =
        json{{"dressed", base + "dressed.glb"}, {"fit", base + "fit.glb"}, {"preview", base + "preview.png"}};
  }
  return out;
}

}  // namespace

std::chrono::milliseconds parse_keep(std::string_view text) {
  long long n = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
  const std::string_view unit(ptr, static_cast<size_t>(text.data() + text.size() - ptr));
  long long seconds_per_unit = 0;
  if (unit == "s")
    seconds_per_unit = 1;
  else if (unit == "m")
    seconds_per_unit = 60;
  else if (unit == "h")
    seconds_per_unit = 3600;
  else if (unit == "d")
    seconds_per_unit = 86400;
  if (ec != std::errc() || ptr == text.data() || n <= 0 || seconds_per_unit == 0 ||
      n > 3650 * 86400 / seconds_per_unit)
    throw InputError("--keep", "'" + std::string(text) + "' is not a duration like 90s, 30m, 24h or 7d");
  return std::chrono::seconds(n * seconds_per_unit);
}

struct WebServer::Impl {
  ServeOptions options;
  web::Catalogue catalogue;
  web::TryOnService service;
  httplib::Server http;
  std::thread listener;
  std::atomic<bool> stopped{false};

  explicit Impl(ServeOptions o)
      : options(std::move(o)), catalogue(options.catalogue_dir), service(options, catalogue) {
    routes();
  }

  void routes();
  void post_body(const httplib::Request& req, httplib::Response& res);
  void post_tryon(const httplib::Request& req, httplib::Response& res);
};

void WebServer::Impl::routes() {
  http.set_payload_max_length(options.max_upload_bytes);
  http.set_read_timeout(30, 0);
  http.set_write_timeout(30, 0);
  http.set_default_headers({{"X-Content-Type-Options", "nosniff"}, {"Referrer-Policy", "no-referrer"}});
  // Statuses httplib answers itself (no route, 413 for a body over the limit) get the API's shape.
  http.set_error_handler(
      httplib::Server::HandlerWithResponse([](const httplib::Request&, httplib::Response& res) {
        if (res.body.empty()) send_error(res, res.status, status_message(res.status));
        return httplib::Server::HandlerResponse::Handled;
      }));
  http.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
    try {
      std::rethrow_exception(ep);
    } catch (const web::RequestError& e) {
      send_error(res, e.status(), e.what());
      if (e.status() == 503) res.set_header("Retry-After", "60");
    } catch (const InputError& e) {
      send_error(res, 400, e.what());
    } catch (const std::exception& e) {
      // Internals (paths, library states) go to the server's log, never to the shopper.
      std::fprintf(stderr, "drape serve: %s\n", e.what());
      send_error(res, 500, status_message(500));
    } catch (...) {
      send_error(res, 500, status_message(500));
    }
  });

  http.Get("/api/health", [this](const httplib::Request&, httplib::Response& res) {
    const web::ServiceStats s = service.stats();
    send_json(res, 200,
              json{{"status", "ok"},
                   {"version", DRAPE_VERSION},
                   {"workers", s.workers},
                   {"queue", {{"queued", s.queued}, {"running", s.running}, {"capacity", s.capacity}}},
                   {"tryons", {{"done", s.done}, {"failed", s.failed}, {"turned_away", s.rejected}}},
                   {"warm_up", {{"left", s.warm_up_left}, {"kept", s.warm_up_kept}}}});
  });

  http.Get("/api/garments", [this](const httplib::Request&, httplib::Response& res) {
    json list = json::array();
    for (const web::CatalogueEntry& e : catalogue.entries()) {
      json chart = json::array();
      for (size_t i = 0; i < e.spec.size_chart.size() && i < e.spec.sizes.size(); ++i)
        chart.push_back(e.spec.sizes[i]);
      list.push_back(json{{"name", e.name},
                          {"description", e.description},
                          {"fabric", e.fabric},
                          {"colour", e.colour},
                          {"sizes", e.spec.sizes},
                          {"base_size", e.spec.sizes.at(e.spec.base_size)},
                          {"size_chart", !e.spec.size_chart.empty()},
                          {"builtin", e.builtin},
                          {"thumbnail", "/api/garments/" + e.name + "/thumbnail.png"}});
    }
    send_json(res, 200, json{{"garments", list}});
  });

  http.Get(R"(/api/garments/([^/]+)/thumbnail\.png)",
           [this](const httplib::Request& req, httplib::Response& res) {
             const web::CatalogueEntry* e = catalogue.find(req.matches[1]);
             if (!e) return send_error(res, 404, "no such garment");
             const auto png = catalogue.thumbnail(*e);
             res.set_content(*png, "image/png");
             res.set_header("Cache-Control", "public, max-age=3600");
           });

  http.Post("/api/bodies",
            [this](const httplib::Request& req, httplib::Response& res) { post_body(req, res); });

  http.Get(R"(/api/bodies/([^/]+))", [this](const httplib::Request& req, httplib::Response& res) {
    const auto body = web::is_id(req.matches[1].str()) ? service.body(req.matches[1]) : std::nullopt;
    if (!body) return send_error(res, 404, "no such body (it may have expired or been deleted)");
    send_json(res, 200, body_json(*body));
    res.set_header("Cache-Control", "private, no-store");
  });

  http.Get(R"(/api/bodies/([^/]+)/([a-z.]+))", [this](const httplib::Request& req, httplib::Response& res) {
    const auto path =
        web::is_id(req.matches[1].str()) ? service.body_file(req.matches[1], req.matches[2]) : std::nullopt;
    if (!path || !send_file(res, *path)) send_error(res, 404, "no such body file");
  });

  http.Delete(R"(/api/bodies/([^/]+))", [this](const httplib::Request& req, httplib::Response& res) {
    if (!web::is_id(req.matches[1].str()) || !service.delete_body(req.matches[1]))
      return send_error(res, 404, "no such body (it may have expired or been deleted)");
    res.status = 204;
  });

  http.Post("/api/tryons",
            [this](const httplib::Request& req, httplib::Response& res) { post_tryon(req, res); });

  http.Get(R"(/api/tryons/([^/]+))", [this](const httplib::Request& req, httplib::Response& res) {
    const auto t = web::is_id(req.matches[1].str()) ? service.tryon(req.matches[1]) : std::nullopt;
    if (!t) return send_error(res, 404, "no such try-on (it may have expired or been deleted)");
    send_json(res, 200, tryon_json(*t));
    res.set_header("Cache-Control", "private, no-store");
  });

  http.Get(R"(/api/tryons/([^/]+)/([a-z.]+))", [this](const httplib::Request& req, httplib::Response& res) {
    const std::string id = req.matches[1];
    const auto t = web::is_id(id) ? service.tryon(id) : std::nullopt;
    if (!t) return send_error(res, 404, "no such try-on (it may have expired or been deleted)");
    const auto path = service.tryon_file(id, req.matches[2]);
    if (!path && t->state != web::TryOnState::Done && t->state != web::TryOnState::Failed)
      return send_error(res, 409, "the try-on is not finished yet");
    if (!path || !send_file(res, *path)) send_error(res, 404, "no such try-on file");
  });

  // The page: index.html, its scripts and styles, and three.js from the npm package (no CDN).
  if (!options.web_root.empty()) {
    if (!std::filesystem::is_regular_file(options.web_root / "index.html"))
      throw InputError(options.web_root.string(), "no index.html in the web folder");
    const std::filesystem::path index = options.web_root / "index.html";
    http.Get("/", [index](const httplib::Request&, httplib::Response& res) {
      if (!send_file(res, index)) return send_error(res, 404, "not found");
      res.set_header("Content-Type", "text/html; charset=utf-8");
      res.set_header("Cache-Control", "no-cache");
    });
    http.set_mount_point("/static", (options.web_root / "static").string());
    const std::filesystem::path three = options.web_root / "node_modules" / "three";
    if (std::filesystem::is_directory(three)) {
      http.set_mount_point("/three/build", (three / "build").string());
      http.set_mount_point("/three/addons", (three / "examples" / "jsm").string());
    } else {
      std::fprintf(stderr, "drape serve: %s is missing (run `make deps`): the page cannot show 3D\n",
                   three.string().c_str());
    }
    http.set_file_extension_and_mimetype_mapping("mjs", "text/javascript");
  }
}

void WebServer::Impl::post_body(const httplib::Request& req, httplib::Response& res) {
  Body body = req.is_multipart_form_data()
                  ? web::body_from_upload(web::upload_from_form(req), options.max_upload_triangles)
                  : web::body_from_measurements(web::parse_body_request(req.body));
  send_json(res, 201, body_json(service.add_body(std::move(body))));
  res.set_header("Cache-Control", "private, no-store");
}

void WebServer::Impl::post_tryon(const httplib::Request& req, httplib::Response& res) {
  const web::TryOnRequest request = web::parse_tryon_request(req.body);
  try {
    const auto submitted = service.submit(request.body, request.garment, request.size);
    send_json(res, submitted.cached ? 200 : 202, json{{"id", submitted.id}, {"cached", submitted.cached}});
  } catch (const web::RequestError& e) {
    send_error(res, e.status(), e.what());
    if (e.status() == 503) res.set_header("Retry-After", std::to_string(service.retry_after_seconds()));
  }
}

WebServer::WebServer(ServeOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}

WebServer::~WebServer() {
  stop();
}

int WebServer::bind(const std::string& host, int port) {
  const int bound =
      port == 0 ? impl_->http.bind_to_any_port(host) : (impl_->http.bind_to_port(host, port) ? port : -1);
  if (bound < 0) throw std::runtime_error(fmt::format("cannot listen on {}:{} (in use?)", host, port));
  return bound;
}

void WebServer::listen() {
  impl_->http.listen_after_bind();
}

void WebServer::start() {
  // bind() already listens: connections made before the accept loop runs wait in the backlog.
  impl_->listener = std::thread([this] { impl_->http.listen_after_bind(); });
}

void WebServer::stop() {
  if (!impl_ || impl_->stopped.exchange(true)) return;
  impl_->http.stop();
  if (impl_->listener.joinable()) impl_->listener.join();
  impl_->service.stop();
}

}  // namespace drape
