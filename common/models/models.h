// Everything a user of the models needs: the Model interface with its optional
// capabilities, ModelParams with its schema, and the registry with MakeModel (see
// models/registry.h).
#pragma once

#include "models/band_assembly_capability.h"
#include "models/contact_capability.h"
#include "models/frames_capability.h"
#include "models/grasp_torque_capability.h"
#include "models/history_capability.h"
#include "models/model.h"
#include "models/params.h"
#include "models/registry.h"
#include "models/symmetry_capability.h"
