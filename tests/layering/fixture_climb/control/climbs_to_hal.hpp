// Fixture: a relative climb must not hide an include of hal/ from control/.
#pragma once
#include "control/../hal/pwm.hpp"
