// `drape serve`: the web try-on (docs/web.md). An HTTP server with the JSON API of DESIGN.md and the
// shoppers' page; try-ons are dressed by a pool of workers through a bounded queue.
#include <pthread.h>

#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "commands.hpp"
#include "drape/error.hpp"
#include "drape/web.hpp"

namespace drape::app {
namespace {

struct ServeArgs {
  int port = 8080;
  std::string host = "127.0.0.1";
  std::string data = "serve-data";
  std::string catalogue;
  std::string web = DRAPE_WEB_ROOT;
  int workers = 0;
  size_t queue = 0;
  std::string keep = "24h";
  std::string queue_url;
  std::string lease = "10s";
  bool worker_only = false;
  double edge = kPaperEdgeLength;
  uint64_t max_iterations = 0;
  size_t max_upload_mb = 64;
  bool warm_up = true;
  bool self_collision = false;
};

void run_serve(const ServeArgs& a) {
  if (!(a.edge >= 0.002 && a.edge <= 0.2))
    throw InputError("--edge", "the edge length must be in [0.002, 0.2] m");
  ServeOptions o;
  o.data_dir = a.data;
  o.catalogue_dir = a.catalogue;
  o.web_root = a.web;
  o.workers = a.workers;
  o.queue_capacity = a.queue;
  o.keep = parse_keep(a.keep);
  o.max_upload_bytes = a.max_upload_mb << 20;
  o.dress.mesh.edge_length = a.edge;
  o.dress.max_iterations = a.max_iterations;
  o.queue_url = a.queue_url;
  o.lease = parse_keep(a.lease);
  o.warm_up = a.warm_up;
  o.dress.self_collision = a.self_collision;
  // SIGINT and SIGTERM stop the server cleanly (workers joined, no half-written try-on left): they
  // are blocked in every thread (the server's inherit the mask) and awaited by one that stops it.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  if (a.worker_only) {
    QueueWorkers workers(o);
    std::printf("drape serve: worker-only, dressing try-ons from %s\n", a.queue_url.c_str());
    std::fflush(stdout);
    int received = 0;
    sigwait(&signals, &received);
    std::fprintf(stderr, "drape serve: stopping after the try-ons being dressed\n");
    workers.stop();
    return;
  }
  WebServer server(o);
  const int port = server.bind(a.host, a.port);
  // The first line on stdout says where to go (tests read the port from it when --port 0).
  std::printf("drape serve: listening on http://%s:%d/ (data in %s)\n", a.host.c_str(), port, a.data.c_str());
  std::fflush(stdout);
  std::thread watcher([&] {
    int received = 0;
    sigwait(&signals, &received);
    std::fprintf(stderr, "drape serve: stopping\n");
    server.stop();
  });
  server.listen();
  watcher.join();
}

}  // namespace

void add_serve_command(CLI::App& app) {
  auto args = std::make_shared<ServeArgs>();
  CLI::App* cmd = app.add_subcommand("serve", "Serve the web try-on: the shoppers' page and its JSON API");
  cmd->add_option("--port", args->port, "TCP port (0: any free port, printed on the first line)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--host", args->host, "address to listen on (0.0.0.0: every interface)")
      ->capture_default_str();
  cmd->add_option("--data", args->data,
                  "folder for bodies, try-on results (private; removed on expiry and on request)")
      ->capture_default_str();
  cmd->add_option("--catalogue", args->catalogue,
                  "folder of garment files (drape JSON, GarmentCode, DXF) offered "
                  "beside the built-ins, each named by its file name");
  cmd->add_option("--web", args->web, "folder of the page (index.html, static/, node_modules/three)")
      ->capture_default_str();
  cmd->add_option(
         "--workers", args->workers,
         "try-ons dressed at once (0: one per core; -1: none, with --queue: worker-only processes dress)")
      ->capture_default_str()
      ->check(CLI::Range(-1, 256));
  cmd->add_option("--queue-size", args->queue,
                  "try-ons that may wait for a worker; more are answered 503 with "
                  "Retry-After (0: four per worker)")
      ->capture_default_str();
  cmd->add_option("--keep", args->keep, "how long a body and its try-ons are kept: 90s, 30m, 24h, 7d")
      ->capture_default_str();
  cmd->add_option(
      "--queue", args->queue_url,
      "shared job queue, redis://HOST:PORT: try-ons go through Redis and `drape serve --worker-only` "
      "processes on other machines share the work (default: an in-process queue)");
  cmd->add_flag(
      "--worker-only", args->worker_only,
      "serve no HTTP: dress try-ons from --queue with --workers workers (same --catalogue as the server)");
  cmd->add_option(
         "--lease", args->lease,
         "with --queue: a worker silent this long is taken for dead and its try-on queued again (e.g. 10s)")
      ->capture_default_str();
  cmd->add_option("--edge", args->edge, "cloth edge length of try-ons in metres (larger: faster, coarser)")
      ->capture_default_str();
  cmd->add_option(
         "--max-iterations", args->max_iterations,
         "cap on each try-on's iterations per garment (0: none; a capped try-on fails the settled check)")
      ->capture_default_str();
  cmd->add_flag("--self-collision", args->self_collision,
               "dress try-ons with self-contact, so that no garment passes through itself (as `drape dress` "
               "does; off by default here: four shoppers at once then wait up to ~2 s at the 95th percentile)");
  cmd->add_flag("!--no-warm-up", args->warm_up,
                "start cold: without first dressing the catalogue on the default bodies as starts for "
                "shoppers' try-ons (the warm-up goes on while no shopper waits)");
  cmd->add_option("--max-upload-mb", args->max_upload_mb, "largest request body in MiB (larger: 413)")
      ->capture_default_str()
      ->check(CLI::Range(1, 1024));
  cmd->callback([args] { run_serve(*args); });
}

}  // namespace drape::app
