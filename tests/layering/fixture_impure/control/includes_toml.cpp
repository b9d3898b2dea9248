// Fixture: control/ links Eigen only. The layering check has to reject this file.
#include <Eigen/Core>
#include <toml++/toml.h>
