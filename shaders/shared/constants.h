// Constants shared by GLSL and C++.
#ifndef TY_SHARED_CONSTANTS_H
#define TY_SHARED_CONSTANTS_H

#include "compat.h"

TY_BEGIN

TY_CONST float kPi = 3.14159265358979323846f;
TY_CONST float kTwoPi = 6.28318530717958647692f;
TY_CONST float kFourPi = 12.5663706143591729539f;
TY_CONST float kInvPi = 0.31830988618379067154f;
TY_CONST float kInvTwoPi = 0.15915494309189533577f;
TY_CONST float kInvFourPi = 0.07957747154594766788f;
TY_CONST float kOneMinusEpsilon = 0.99999994f;  // the largest float below 1
TY_CONST float kInfinity = 3.402823466e38f;     // FLT_MAX: GLSL has no portable infinity literal

TY_END

#endif  // TY_SHARED_CONSTANTS_H
