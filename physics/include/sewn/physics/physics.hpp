#pragma once
// Everything of sewn::physics in one include.

#include "sewn/physics/basic_terms.hpp"
#include "sewn/physics/block_matrix.hpp"
#include "sewn/physics/cg.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/force_term.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/physics/integrate/energy_ledger.hpp"
#include "sewn/physics/integrate/implicit_midpoint.hpp"
#include "sewn/physics/lattice.hpp"
#include "sewn/physics/nodes.hpp"
#include "sewn/physics/solve/linear_solver.hpp"
#include "sewn/physics/springs.hpp"
#include "sewn/physics/stiffness.hpp"
#include "sewn/physics/system.hpp"
#include "sewn/physics/threads.hpp"
#include "sewn/physics/types.hpp"
