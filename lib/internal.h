/*
 * libodhs internal declarations: the umbrella over every module's private
 * header, for tests and benchmarks that look inside the library (they link
 * the static archive). Library sources include only the module headers they
 * need. Not installed.
 */
#ifndef ODHS_INTERNAL_H
#define ODHS_INTERNAL_H

#include "base/base.h"
#include "geom/geom.h"
#include "system/system.h"
#include "network/network.h"
#include "solvers/solvers.h"
#include "jamming/jamming.h"
#include "softcore/softcore.h"
#include "driver/driver.h"
#include "stepper/stepper.h"
#include "io/ckpt.h"

#endif /* ODHS_INTERNAL_H */
