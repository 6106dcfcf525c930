// The equilibrium next to a state, at round-off, by the model and a linear solver alone:
// the truth the accuracy tools (snapthread-accuracy, the path bench) compare rows with.
#pragma once

#include "models/model.h"

namespace snapthread {

// Damped Newton steps (E_xx + mu I) dx = -E_x from x while |E_x| falls (mu from 0, x10
// on a refused step, /100 on a kept one; 12 refusals in a row or 200 steps end it): the
// equilibrium next to x at round-off. Independent of the solvers: the model and a linear
// solver only. Defined in accuracy_matrix.cc.
Vec PolishToRoundOff(const Model& model, const Vec& u, Vec x);

}  // namespace snapthread
