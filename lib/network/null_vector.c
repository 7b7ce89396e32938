/* libodhs - the public self-stress call of a network (include/odhs/network.h);
 * the numerics are lib/jamming/selfstress.c's. */
#include "jamming/jamming.h"

int odhs_network_null_vector(const odhs_network *net, odhs_solver *solver, double *f0, double *residual)
{
    if (!net) return ODHS_E_NULL;
    if (!f0 && net->nc) return odhs__neterr(net, ODHS_E_NULL, "output pointer is NULL");
    return odhs__null_vector(net, solver, f0, residual);
}
