// Everything a user of the models needs: the Model interface, ModelParams with its
// schema, and the registry with MakeModel (see models/registry.h).
#pragma once

#include "models/model.h"
#include "models/params.h"
#include "models/registry.h"
