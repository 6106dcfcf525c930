// What the in-process server tests (server_test.cc) observe and send: a probe that
// collects the server's force models, shapes and statuses from an in-memory transport
// (server_memory_transport.h), and a device pose.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "messages/validate.h"
#include "server_memory_transport.h"
#include "snapthread/device_state_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::server::server_test_support {

// Generous: the machine is shared and noisy.
inline constexpr std::chrono::seconds kWait{20};

// Collects what the server publishes, decoded and validated as a receiver would. It
// listens on the server's solve thread; make it before the server starts and keep it
// until the server stopped.
class Probe {
 public:
  explicit Probe(testing::MemoryServerTransport* transport) {
    transport->AddListener([this](testing::Outbound channel, const std::vector<uint8_t>& bytes) {
      switch (channel) {
        case testing::Outbound::kForceModel:
          Keep<force_model_t>(bytes, &models_);  // DecodeAndValidate: the one force-model check
          break;
        case testing::Outbound::kShape:
          Keep<thread_shape_t>(bytes, &shapes_);
          break;
        case testing::Outbound::kSolverStatus:
          Keep<solver_status_t>(bytes, &statuses_);
          break;
        case testing::Outbound::kCommandReply:  // server_commands_test checks replies
          break;
      }
    });
  }

  // Waits for a force model answering device_seq.
  bool WaitModel(int64_t device_seq, force_model_t* out) {
    return WaitFirst<force_model_t>(models_, 0, [&](const force_model_t& m) { return m.device_seq == device_seq; },
                                    out);
  }
  // Waits until pred(shapes or statuses) holds for a message received after `since`
  // messages of that kind.
  bool WaitShape(size_t since, const std::function<bool(const thread_shape_t&)>& pred,
                 thread_shape_t* out = nullptr) {
    return WaitFirst(shapes_, since, pred, out);
  }
  bool WaitStatus(size_t since, const std::function<bool(const solver_status_t&)>& pred) {
    return WaitFirst<solver_status_t>(statuses_, since, pred, nullptr);
  }
  std::vector<force_model_t> models() {
    std::lock_guard<std::mutex> lock(mutex_);
    return models_;
  }
  size_t num_shapes() {
    std::lock_guard<std::mutex> lock(mutex_);
    return shapes_.size();
  }
  size_t num_statuses() {
    std::lock_guard<std::mutex> lock(mutex_);
    return statuses_.size();
  }
  int invalid() {
    std::lock_guard<std::mutex> lock(mutex_);
    return invalid_;
  }

 private:
  // Decodes and validates a message into *kept; counts the rest.
  template <typename T>
  void Keep(const std::vector<uint8_t>& bytes, std::vector<T>* kept) {
    T msg;
    std::string why;
    const bool ok =
        messages::DecodeAndValidate(bytes.data(), static_cast<int>(bytes.size()), &msg, &why);
    std::lock_guard<std::mutex> lock(mutex_);
    if (!ok) {
      ++invalid_;
      return;
    }
    kept->push_back(msg);
    cv_.notify_all();
  }
  // Waits until pred holds for a message of `kept` from index `since` on (copied to *out).
  template <typename T>
  bool WaitFirst(const std::vector<T>& kept, size_t since, const std::function<bool(const T&)>& pred, T* out) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, kWait, [&] {
      for (size_t i = since; i < kept.size(); ++i) {
        if (pred(kept[i])) {
          if (out) *out = kept[i];
          return true;
        }
      }
      return false;
    });
  }

  std::mutex mutex_;
  std::condition_variable cv_;
  std::vector<force_model_t> models_;
  std::vector<thread_shape_t> shapes_;
  std::vector<solver_status_t> statuses_;
  int invalid_ = 0;
};

inline device_state_t MakePose(int64_t seq, const Eigen::Vector3d& p,
                        const Eigen::Vector4d& q = Eigen::Vector4d(1, 0, 0, 0)) {
  device_state_t s;
  s.utime = 1000 + seq;
  s.seq = seq;
  s.device_id = "test";
  for (int i = 0; i < 3; ++i) s.position[i] = p[i];
  for (int i = 0; i < 4; ++i) s.orientation[i] = q[i];
  s.buttons = 1;
  return s;
}

}  // namespace snapthread::server::server_test_support
