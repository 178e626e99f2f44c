#pragma once
// Tissue constitutive models for the finite element solvers (2-D axisymmetric and 3-D).
// Everything in SI: moduli in Pa, energy density in J/m^3.

#include <Eigen/Core>

#include "mneedle/base/material_model.h"

namespace mneedle::fe {

/// Constants of one tissue layer. E (Pa) and nu set the small-strain response of every model.
/// Mooney-Rivlin: W = c10 (I1bar - 3) + c01 (I2bar - 3) + kappa/2 (ln J)^2 with
/// kappa = E / (3 (1 - 2 nu)); when c10 + c01 == 0 the shear part is taken from E and nu
/// (c10 = mu / 2, c01 = 0), otherwise the small-strain shear modulus is 2 (c10 + c01).
struct MaterialParameters {
  MaterialModel model = MaterialModel::Linear;
  double E = 0.0;
  double nu = 0.0;
  double c10 = 0.0;
  double c01 = 0.0;
};

/// Stress and tangent at one material point. Voigt order xx, yy, zz, yz, xz, xy; strain in Voigt
/// form uses engineering shear (2 E_yz ...), so S_voigt = C * E_voigt for a linear law.
struct MaterialResponse {
  Eigen::Matrix3d S;              ///< second Piola-Kirchhoff stress (Pa)
  Eigen::Matrix<double, 6, 6> C;  ///< dS/dE, E the Green-Lagrange strain (Pa)
  double energy_density = 0.0;    ///< strain energy per reference volume (J/m^3)
};

class Material {
 public:
  /// Validates the constants: E > 0, -1 < nu < 0.5, c10, c01 >= 0, all finite; else InputError.
  explicit Material(const MaterialParameters& parameters);

  /// F is the deformation gradient. Linear uses the small strain sym(F) - I (and returns the
  /// Cauchy = PK2 stress of linear elasticity); the others use E = (F^T F - I) / 2.
  /// Throws SolverError when det F <= 0 for a hyperelastic model (an inverted element).
  MaterialResponse evaluate(const Eigen::Matrix3d& F) const;

  /// True for the small-strain model: the solvers use linear kinematics and skip Newton.
  bool is_linear() const;

  const MaterialParameters& parameters() const { return parameters_; }
  /// Small-strain Lame constants (Pa).
  double lambda() const { return lambda_; }
  double mu() const { return mu_; }

 private:
  MaterialParameters parameters_;
  double lambda_ = 0.0;
  double mu_ = 0.0;
  double kappa_ = 0.0;
};

/// Isotropic small-strain elasticity matrix (Voigt, engineering shear) from E and nu.
Eigen::Matrix<double, 6, 6> isotropic_elasticity(double E, double nu);

}  // namespace mneedle::fe
