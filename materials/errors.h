#pragma once
// The error types now live in core/errors.h (the ground floor every library may use). This header
// forwards to it so that engine/, which still includes it, builds unchanged; new code includes
// core/errors.h.
#include "core/errors.h"
