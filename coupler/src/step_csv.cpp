#include "angio/coupler/step_csv.hpp"

#include <iomanip>
#include <stdexcept>

namespace angio::coupler {

StepCsv::StepCsv(const std::string& path) : out_(path) {
  if (!out_) throw std::runtime_error(path + ": cannot open for writing");
  out_ << "step,time,pressure,coupling_iterations,residual,omega,cuts,converged,beam_time,"
          "solid_time,messaging_time,wall_time,n_active,min_gap,contact_force_x,contact_force_y,"
          "contact_force_z,restarts,products,product_time\n";
  out_.flush();
}

void StepCsv::write(const StepReport& r, double pressure, double messaging) {
  out_ << std::setprecision(10) << r.step << ',' << r.time << ',' << pressure << ',' << r.iterations << ','
       << (r.residuals.empty() ? 0.0 : r.residuals.back()) << ',' << r.omega << ',' << r.cuts << ','
       << (r.converged ? 1 : 0) << ',' << r.beam_time << ',' << r.solid_time << ',' << messaging << ',' << r.wall_time
       << ',' << r.contact.n_active << ',' << r.contact.min_gap << ',' << r.contact.total_force[0] << ','
       << r.contact.total_force[1] << ',' << r.contact.total_force[2] << ',' << r.restarts << ',' << r.products << ','
       << r.product_time << '\n';
  // Flushed per step: a run that fails later leaves every committed step readable.
  out_.flush();
}

}  // namespace angio::coupler
