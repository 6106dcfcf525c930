// The JSON text the page receives for each session message (one WebSocket text message
// each, "type" naming the kind; web/page/src/ reads them). Every field the page draws or
// charts is here; the authentication fields (epoch, auth_seq, mac) are not.
#pragma once

#include <string>

#include "snapthread/device_status_t.hpp"
#include "snapthread/force_model_t.hpp"
#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::web {

// `smooth`: draw a curve through the nodes (the registry's chain models) rather than
// straight rods between them (Zeeman, cusp), as the native viewer does.
std::string ShapeJson(const thread_shape_t& shape, bool smooth);
std::string ForceModelJson(const force_model_t& model);
std::string SolverStatusJson(const solver_status_t& status);
std::string DeviceStatusJson(const device_status_t& status);

// Whether the native viewer draws this model's nodes as a smooth curve (models registry).
bool DrawsSmooth(const std::string& model);

}  // namespace snapthread::web
