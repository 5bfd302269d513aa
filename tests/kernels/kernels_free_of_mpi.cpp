// Compiled on its own (not linked): the kernel and law headers must build without MPI, Tpetra or
// Teuchos. If any of them (or a header it includes) pulls one in, this file fails to compile.
#include "mupm/kernels/boundary_conditions.hpp"
#include "mupm/kernels/central_difference.hpp"
#include "mupm/kernels/damage.hpp"
#include "mupm/kernels/fluid.hpp"
#include "mupm/kernels/fracture.hpp"
#include "mupm/kernels/fracture_flow.hpp"
#include "mupm/kernels/j_integral.hpp"
#include "mupm/kernels/shape_tensor.hpp"
#include "mupm/kernels/shear_bands.hpp"
#include "mupm/kernels/solid.hpp"
#include "mupm/kernels/solid_energy.hpp"
#include "mupm/laws/micropolar_drucker_prager.hpp"
#include "mupm/laws/micropolar_elastic.hpp"
#include "mupm/laws/stabilization.hpp"
#include "mupm/laws/unsaturated.hpp"

#if defined(MPI_VERSION) || defined(OMPI_MPI_H) || defined(MPI_INCLUDED)
#error "a kernel header includes mpi.h"
#endif
#if defined(TPETRA_MAP_DECL_HPP) || defined(TPETRA_IMPORT_DECL_HPP) || defined(TEUCHOS_COMM_HPP)
#error "a kernel header includes Tpetra or Teuchos"
#endif
