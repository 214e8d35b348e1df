#include "web/redis_queue.hpp"

#include <hiredis/hiredis.h>

#include <charconv>
#include <stdexcept>

#include "drape/error.hpp"

namespace drape::web {
namespace {

constexpr const char* kQueue = "drape:queue";

std::string ms(std::chrono::milliseconds d) {
  return std::to_string(std::max<long long>(1, d.count()));
}

}  // namespace

RedisConnection::RedisConnection(const std::string& url) {
  const std::string scheme = "redis://";
  if (!url.starts_with(scheme)) throw InputError("--queue", "expected redis://HOST:PORT, got '" + url + "'");
  std::string host = url.substr(scheme.size());
  if (!host.empty() && host.back() == '/') host.pop_back();
  int port = 6379;
  if (const size_t colon = host.rfind(':'); colon != std::string::npos) {
    const std::string digits = host.substr(colon + 1);
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), port);
    if (ec != std::errc() || end != digits.data() + digits.size() || port <= 0 || port > 65535)
      throw InputError("--queue", "'" + digits + "' is not a port");
    host.resize(colon);
  }
  if (host.empty()) throw InputError("--queue", "expected redis://HOST:PORT, got '" + url + "'");
  const timeval timeout{5, 0};
  context_ = redisConnectWithTimeout(host.c_str(), port, timeout);
  if (!context_ || context_->err) {
    const std::string why = context_ ? context_->errstr : "out of memory";
    redisFree(context_);
    context_ = nullptr;
    throw std::runtime_error("cannot reach Redis at " + host + ":" + std::to_string(port) + ": " + why);
  }
}

RedisConnection::~RedisConnection() {
  redisFree(context_);
}

RedisConnection::Reply RedisConnection::command(const std::vector<std::string>& args) {
  std::vector<const char*> argv;
  std::vector<size_t> lengths;
  for (const std::string& a : args) {
    argv.push_back(a.data());
    lengths.push_back(a.size());
  }
  auto* reply = static_cast<redisReply*>(
      redisCommandArgv(context_, static_cast<int>(args.size()), argv.data(), lengths.data()));
  if (!reply)
    throw std::runtime_error(std::string("Redis: ") +
                             (context_->errstr[0] ? context_->errstr : "connection lost"));
  std::unique_ptr<redisReply, void (*)(void*)> owned(reply, freeReplyObject);
  const auto text = [](const redisReply* r) -> std::optional<std::string> {
    switch (r->type) {
      case REDIS_REPLY_STRING:
      case REDIS_REPLY_STATUS:
        return std::string(r->str, r->len);
      case REDIS_REPLY_INTEGER:
        return std::to_string(r->integer);
      default:
        return std::nullopt;
    }
  };
  if (reply->type == REDIS_REPLY_ERROR)
    throw std::runtime_error("Redis: " + std::string(reply->str, reply->len));
  Reply out;
  out.value = text(reply);
  if (reply->type == REDIS_REPLY_ARRAY)
    for (size_t i = 0; i < reply->elements; ++i) out.elements.push_back(text(reply->element[i]));
  return out;
}

void RedisQueue::put_body(const std::string& id, const std::string& glb, std::chrono::milliseconds keep) {
  redis_.command({"SET", "drape:body:" + id, glb, "PX", ms(keep)});
}

void RedisQueue::delete_body(const std::string& id) {
  redis_.command({"DEL", "drape:body:" + id});
}

size_t RedisQueue::queued() {
  return std::stoul(redis_.command({"LLEN", kQueue}).value.value_or("0"));
}

std::string RedisQueue::push(const RedisJob& job) {
  const nlohmann::json j{{"tryon", job.tryon},
                         {"body", job.body},
                         {"garment", job.garment},
                         {"size", job.size},
                         {"reply", job.reply}};
  std::string text = j.dump();
  redis_.command({"RPUSH", kQueue, text});
  return text;
}

void RedisQueue::remove(const std::string& job) {
  redis_.command({"LREM", kQueue, "0", job});
}

std::optional<std::string> RedisQueue::pop_done(const std::string& reply, std::chrono::milliseconds wait) {
  const auto r = redis_.command({"BLPOP", reply, std::to_string(static_cast<double>(wait.count()) / 1000.0)});
  if (r.elements.size() != 2 || !r.elements[1]) return std::nullopt;
  return r.elements[1];
}

std::optional<RedisResult> RedisQueue::take_result(const std::string& tryon) {
  const std::string key = "drape:result:" + tryon;
  const auto r = redis_.command({"HGETALL", key});
  redis_.command({"DEL", key, "drape:progress:" + tryon});
  if (r.elements.empty()) return std::nullopt;
  RedisResult out;
  out.tryon = tryon;
  for (size_t i = 0; i + 1 < r.elements.size(); i += 2) {
    const std::string field = r.elements[i].value_or(""), value = r.elements[i + 1].value_or("");
    if (field == "state")
      out.done = value == "done";
    else if (field == "size")
      out.size = value;
    else if (field == "error")
      out.error = value;
    else if (field == "report")
      out.report = nlohmann::json::parse(value, nullptr, false);
    else if (field.starts_with("file:"))
      out.files.emplace_back(field.substr(5), value);
  }
  return out;
}

std::optional<double> RedisQueue::progress(const std::string& tryon) {
  const auto r = redis_.command({"GET", "drape:progress:" + tryon});
  if (!r.value) return std::nullopt;
  return std::stod(*r.value);
}

size_t RedisQueue::requeue_abandoned() {
  size_t moved = 0;
  for (const auto& worker : redis_.command({"SMEMBERS", "drape:workers"}).elements) {
    if (!worker || redis_.command({"EXISTS", "drape:alive:" + *worker}).value == "1") continue;
    const std::string processing = "drape:processing:" + *worker;
    while (redis_.command({"LMOVE", processing, kQueue, "RIGHT", "LEFT"}).value) ++moved;
    redis_.command({"SREM", "drape:workers", *worker});
  }
  return moved;
}

void RedisQueue::renew_lease(const std::string& worker, std::chrono::milliseconds lease) {
  redis_.command({"SET", "drape:alive:" + worker, "1", "PX", ms(lease)});
  redis_.command({"SADD", "drape:workers", worker});
}

std::optional<RedisJob> RedisQueue::take(const std::string& worker, std::chrono::milliseconds wait) {
  const auto r = redis_.command({"BLMOVE", kQueue, "drape:processing:" + worker, "LEFT", "RIGHT",
                                 std::to_string(static_cast<double>(wait.count()) / 1000.0)});
  if (!r.value) return std::nullopt;
  const nlohmann::json j = nlohmann::json::parse(*r.value, nullptr, false);
  RedisJob job;
  job.text = *r.value;
  if (!j.is_object()) return job;  // not a job: finish() drops it with a reason
  job.tryon = j.value("tryon", "");
  job.body = j.value("body", "");
  job.garment = j.value("garment", "");
  job.size = j.value("size", "");
  job.reply = j.value("reply", "");
  return job;
}

std::optional<std::string> RedisQueue::body(const std::string& id) {
  return redis_.command({"GET", "drape:body:" + id}).value;
}

void RedisQueue::set_progress(const std::string& tryon, double progress, std::chrono::milliseconds keep) {
  redis_.command({"SET", "drape:progress:" + tryon, std::to_string(progress), "PX", ms(keep)});
}

void RedisQueue::finish(const std::string& worker, const RedisJob& job, const RedisResult& result,
                        std::chrono::milliseconds keep) {
  const std::string key = "drape:result:" + job.tryon;
  std::vector<std::string> hset{"HSET",   key,
                                "state",  result.done ? "done" : "failed",
                                "size",   result.size,
                                "error",  result.error,
                                "report", result.report.dump()};
  for (const auto& [name, bytes] : result.files) {
    hset.push_back("file:" + name);
    hset.push_back(bytes);
  }
  // The result, its expiry, the server's notice and the job's removal from this worker's list
  // happen together: a worker that dies before EXEC leaves the job to be taken up again.
  redis_.command({"MULTI"});
  redis_.command(hset);
  redis_.command({"PEXPIRE", key, ms(keep)});
  if (!job.reply.empty()) redis_.command({"RPUSH", job.reply, job.tryon});
  redis_.command({"LREM", "drape:processing:" + worker, "1", job.text});
  redis_.command({"EXEC"});
}

}  // namespace drape::web
