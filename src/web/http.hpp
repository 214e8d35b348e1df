#pragma once
// cpp-httplib, for the server and its tests. httplib includes glibc's <resolv.h>, whose macro
// `_res` (the resolver's per-thread state, which drape never uses) would rename the parameters of
// that name in Eigen's product kernels wherever Eigen is included after it; it is undefined here so
// that include order does not matter.
#include <httplib.h>

#undef _res
