// Vetting of the messages the viewer draws: the transport library's DecodeAndValidate
// (length fields checked before lcm-gen's decoders, counts and finiteness after), plus what
// drawing needs on top (at least one node; material frames, if any, one per edge with a
// unit director). Never throws: called inside LCM handlers.
#pragma once

#include <string>

#include "snapthread/solver_status_t.hpp"
#include "snapthread/thread_shape_t.hpp"

namespace snapthread::viewer {

// False (reason in *why) for anything malformed; *out is meaningful only on true.
bool DecodeShape(const void* data, int size, thread_shape_t* out, std::string* why);
bool DecodeSolverStatus(const void* data, int size, solver_status_t* out, std::string* why);

}  // namespace snapthread::viewer
