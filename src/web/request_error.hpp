#pragma once
// An answer other than success, with the HTTP status and the words the shopper reads. Thrown by
// the service's checks and turned into `{"error": message}` by the server; the message never holds
// a server path or an internal detail.
#include <stdexcept>
#include <string>

namespace drape::web {

class RequestError : public std::runtime_error {
 public:
  RequestError(int status, const std::string& message) : std::runtime_error(message), status_(status) {}
  int status() const noexcept { return status_; }

 private:
  int status_;
};

}  // namespace drape::web
