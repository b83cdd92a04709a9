// Umbrella header of batchcol: a data-parallel batched collision engine for convex shapes.
#pragma once

#include "batchcol/batch.hpp"
#include "batchcol/derivatives.hpp"
#include "batchcol/errors.hpp"
#include "batchcol/io.hpp"
#include "batchcol/pose.hpp"
#include "batchcol/rays.hpp"
#include "batchcol/scene.hpp"
#include "batchcol/shapes.hpp"
