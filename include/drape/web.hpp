#pragma once
// The web try-on (`drape serve`, docs/web.md): an HTTP server with a JSON API and the shoppers' page.
// A shopper makes a body (from measurements or an uploaded scan), picks a garment from the
// catalogue and a size (or "auto": every size dressed and one recommended), and a pool of workers
// dresses the body through a bounded queue; the page polls the try-on and shows dressed.glb.
//
//   drape::ServeOptions options;
//   options.data_dir = "serve-data";
//   drape::WebServer server(options);
//   const int port = server.bind("127.0.0.1", 0);   // 0: any free port
//   server.start();                                 // or listen(), which blocks
//
// Privacy: a body is reachable only through its random 128-bit id, never listed; it and every
// try-on of it live under data_dir/bodies/ID/, which DELETE and expiry remove whole.
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "drape/dress.hpp"

namespace drape {

struct ServeOptions {
  std::filesystem::path data_dir = "drape-data";  // bodies, try-on results, thumbnails
  std::filesystem::path catalogue_dir;            // garment files offered beside the built-ins; empty: none
  std::filesystem::path web_root;  // the page (index.html, static/, node_modules/three); empty: API only
  int workers = 0;                 // try-ons dressed at once; 0: one per core; negative:
                                   // none (with queue_url: worker-only processes dress)
  size_t queue_capacity = 0;       // try-ons waiting for a worker; 0: four per worker
  std::chrono::milliseconds keep{std::chrono::hours(24)};  // a body and its try-ons live this long
  size_t max_upload_bytes = 64u << 20;                     // a larger request is refused (413)
  size_t max_upload_triangles = 2'000'000;
  size_t max_bodies = 10'000;  // bodies held at once; more are refused (503) until some expire // a body mesh
                               // with more is refused (413)
  // How try-ons are dressed (mesh edge, iteration cap, ...). Without self-contact by default: with it
  // (docs/cloth.md, "Self-contact"), four shoppers at once waited up to 1.95-2.04 s at the 95th
  // percentile on a restarted server (bench_web), against the 2 s the try-on is to answer within.
  DressOptions dress = [] {
    DressOptions d;
    d.self_collision = false;
    return d;
  }();
  // Shared queue: "redis://HOST:PORT" sends try-ons through Redis, where this server's workers and
  // `drape serve --worker-only` processes take them; empty: the in-process queue. A worker that
  // does not renew its lease for this long is taken for dead and its try-on is queued again.
  std::string queue_url;
  std::chrono::milliseconds lease{std::chrono::seconds(10)};
  // Warm-up: from the start, one idle worker at a time (per process, with a shared queue too)
  // dresses every garment of the catalogue in each size on the default female and male bodies,
  // their chart's sizes first, and keeps each drape that passes as a start for shoppers' try-ons on
  // bodies like them, also in data_dir/starts for the next run (docs/web.md). A shopper's try-on
  // always goes first. `drape serve` turns it on.
  bool warm_up = false;
};

// "90s", "30m", "24h", "7d" (a whole number and a unit). InputError("--keep") otherwise.
std::chrono::milliseconds parse_keep(std::string_view text);

class WebServer {
 public:
  // Loads the catalogue (a garment file that does not load is named on stderr and left out) and
  // starts the workers. Throws InputError for a catalogue folder or web root that does not exist.
  explicit WebServer(ServeOptions options);
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  // Binds to host:port (port 0: a free port chosen by the system); returns the port. Throws
  // std::runtime_error when the address is taken.
  int bind(const std::string& host, int port);
  void listen();  // serves until stop()
  void start();   // serves on a thread of its own
  void stop();    // stops serving, finishes no new try-ons, joins the workers

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// `drape serve --worker-only`: options.workers (0: one per core) workers dressing try-ons from the
// shared queue options.queue_url, with the catalogue of options.catalogue_dir (the same garment
// files as the server's), until stop(). Throws std::runtime_error when Redis cannot be reached.
class QueueWorkers {
 public:
  explicit QueueWorkers(ServeOptions options);
  ~QueueWorkers();
  QueueWorkers(const QueueWorkers&) = delete;
  QueueWorkers& operator=(const QueueWorkers&) = delete;
  void stop();  // finishes the try-ons being dressed

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drape
