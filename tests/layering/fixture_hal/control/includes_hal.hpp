// Fixture: control/ must not include hal/. The layering check has to reject this file.
#pragma once
#include "hal/pwm.hpp"
