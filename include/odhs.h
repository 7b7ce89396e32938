/*
 * libodhs - event-driven simulation of overdamped frictionless hard spheres
 * (Lerner, During and Wyart, 2013). Umbrella header.
 */
#ifndef ODHS_H
#define ODHS_H

#include "odhs/common.h"
#include "odhs/system.h"
#include "odhs/io.h"
#include "odhs/network.h"
#include "odhs/solver.h"
#include "odhs/driver.h"
#include "odhs/stepper.h"
#include "odhs/walls.h"
#include "odhs/composite.h"
#include "odhs/jamming.h"
#include "odhs/checkpoint.h"
#include "odhs/softcore.h"
#include "odhs/traj.h"
#include "odhs/lammps.h"
#include "odhs/analysis.h"

#endif /* ODHS_H */
