#include "gnuplot_plots.h"

#include <filesystem>
#include <fstream>

#include "gnuplot_runner.h"
#include "messages/channels.h"

namespace snapthread::report {
namespace {

// Every script names its files relative to the output directory (gnuplot runs there), so no
// path reaches gnuplot's command language; the only log-derived text is the session name in
// the titles, and only a valid one (SessionLabel).
constexpr char kPreamble[] =
    "set terminal pngcairo size 1100,700 font ',10' noenhanced\n"
    "set datafile separator ','\n"
    "set grid\n"
    "set key top right\n"
    "bin(x,w) = w*floor(x/w) + w/2\n";

// The session for a title: a name of the session grammar ([A-Za-z0-9_], which holds no
// quote, backquote, newline or other gnuplot syntax), else a fixed placeholder. The review's
// session is one already (InferSession, --session), so this is the second wall.
std::string SessionLabel(const std::string& session) {
  return messages::IsValidSessionName(session) ? session : "unnamed session";
}

// Runs one script; on success the PNG must exist and be non-empty.
bool RunGnuplot(const std::string& dir, const std::string& name, const std::string& body,
                PlotOutcome* out) {
  const std::string png = name + ".png";
  std::error_code ec;
  std::filesystem::remove(dir + "/" + png, ec);  // a PNG of an earlier run is no proof
  const GnuplotRun run =
      RunGnuplotScript(dir, name, kPreamble + ("set output '" + png + "'\n") + body);
  const auto size = std::filesystem::file_size(dir + "/" + png, ec);
  if (!run.ok || ec || size == 0) {
    out->notes.push_back(png + " failed: " + (run.ok ? "no image written" : run.problem));
    return false;
  }
  out->written.push_back(png);
  return true;
}

// Adds a note. Out of line: once inlined into the Plot* functions, GCC 12 misreads the
// copy of a long literal into the vector's new string as out of bounds (-Warray-bounds).
[[gnu::noinline]] void AddNote(PlotOutcome* out, const std::string& note) { out->notes.push_back(note); }

// A data file of the output directory, by its fixed name.
std::string Csv(const std::string& name) { return "'" + name + "'"; }

// force_error.png: the certified force error (force_model_t.force_error_n) over time, one
// series per grasp (by index: summary.txt names them; no grasp name reaches the script).
// Models without an estimate ("none" in force.csv) are not drawn.
void PlotForceError(const SessionReview& r, const std::string& dir, const std::string& ch, PlotOutcome* out) {
  if (!r.HasForceError()) {
    AddNote(out, "force_error.png not drawn: no " + ch + "_FORCE_MODEL carries a certified force error (none)");
    return;
  }
  std::string body = "set title 'Certified force error (" + ch + "_FORCE_MODEL force_error_n)'\n"
                     "set xlabel 'time [s]'\nset ylabel 'certified force error [N]'\nset logscale y\n"
                     "set format y '%.0e'\nplot ";
  for (size_t g = 0; g < r.grasps().size(); ++g) {
    const std::string k = std::to_string(g);
    body += std::string(g == 0 ? "" : ", ") + Csv("force.csv") + " skip 1 using 1:($8 == " + k +
            " && $9 > 0 ? $9 : 1/0) with points pt 7 ps 0.4 title 'grasp " + k + "'";
  }
  RunGnuplot(dir, "force_error", body + "\n", out);
}

// force.png: |F| and its components over time, snaps marked.
void PlotForce(const std::string& dir, const SessionReview& r, const std::string& ch, PlotOutcome* out) {
  if (r.HasForce()) {
    std::string body = "set title 'Force on the grasp (" + ch + "_FORCE_MODEL f0); snaps marked'\n"
                       "set xlabel 'time [s]'\nset ylabel 'force [N]'\n"
                       "plot " + Csv("force.csv") + " skip 1 using 1:5 with lines lw 2 title '|F|', "
                       "'' skip 1 using 1:2 with lines title 'Fx', "
                       "'' skip 1 using 1:3 with lines title 'Fy', "
                       "'' skip 1 using 1:4 with lines title 'Fz'";
    // An empty snaps.csv would make gnuplot fail, so the series is added only when present.
    std::ifstream snaps(dir + "/snaps.csv");
    std::string header, first;
    std::getline(snaps, header);
    if (std::getline(snaps, first) && !first.empty()) {
      body += ", " + Csv("snaps.csv") +
              " skip 1 using 1:2 with impulses lw 2 lc rgb 'red' title 'snap', "
              "'' skip 1 using 1:2 with points pt 7 ps 1.5 lc rgb 'red' notitle";
    }
    RunGnuplot(dir, "force", body + "\n", out);
  } else {
    AddNote(out, "force.png not drawn: no " + ch + "_FORCE_MODEL messages");
  }
}

// knot.png: the knot determinant and the active self-contacts over time.
void PlotKnot(const std::string& dir, const SessionReview& r, const std::string& ch, PlotOutcome* out) {
  if (r.HasKnot()) {
    RunGnuplot(dir, "knot",
               "set multiplot layout 2,1 title 'Knot type and self-contacts (" + ch +
                   "_SOLVER_STATUS)'\nset xlabel 'time [s]'\n"
                   "set ylabel 'knot determinant'\nset yrange [0:*]\n"
                   "set ytics add ('unknot 1' 1, 'trefoil 3' 3, 'figure-eight 5' 5)\n"
                   "plot " + Csv("knot.csv") + " skip 1 using 1:3 with steps lw 2 "
                   "title '|Delta(-1)|'\nset ylabel 'active contacts'\n"
                   "set ytics autofreq\nplot '' skip 1 using 1:4 with steps lw 2 lc rgb 'red' "
                   "title 'contacts'\nunset multiplot\n",
               out);
  } else {
    AddNote(out, "knot.png not drawn: no knot type or contacts in the solver status");
  }
}

// solver.png: iterations, residual and method (or solve time) over time.
void PlotSolver(const std::string& dir, const SessionReview& r, const std::string& ch, PlotOutcome* out) {
  if (r.HasSolve() || r.HasSolverStatus()) {
    std::string body = "set multiplot layout 3,1 title 'Solver (" + ch + ")'\nset xlabel 'time [s]'\n";
    if (r.HasSolve()) {
      body += "set ylabel 'iterations'\nplot " + Csv("solve.csv") +
              " skip 1 using 1:2 with steps title 'iterations per update'\n"
              "set logscale y\nset ylabel '||E_x||'\nplot '' skip 1 using 1:($3 > 0 ? $3 : 1e-300) "
              "with points pt 7 ps 0.3 title 'residual'\nunset logscale y\n";
    } else {
      body += "set ylabel 'iterations'\nplot " + Csv("solver_status.csv") +
              " skip 1 using 1:4 with steps title 'iterations'\n"
              "set logscale y\nset ylabel '||E_x||'\nplot '' skip 1 using 1:5 with points "
              "title 'residual'\nunset logscale y\n";
    }
    if (r.HasSolverStatus()) {
      body += "set ylabel 'method'\nset yrange [-0.5:3.5]\n"
              "set ytics ('newton' 0, 'newton-ls' 1, 'higher-order' 2, 'other' 3)\n"
              "plot " + Csv("solver_status.csv") + " skip 1 using 1:3 with steps lw 2 title 'method'\n";
    } else {
      body += "set ylabel 'solve [us]'\nplot " + Csv("solve.csv") +
              " skip 1 using 1:4 with points pt 7 ps 0.3 title 'solve time'\n";
    }
    body += "unset multiplot\n";
    RunGnuplot(dir, "solver", body, out);
  } else {
    AddNote(out, "solver.png not drawn: no force models or solver status");
  }
}

// device.png and latency_hist.png: tick lateness, model age and the latency histograms.
void PlotDevice(const std::string& dir, const SessionReview& r, const std::string& ch, PlotOutcome* out) {
  if (r.HasDevice()) {
    const std::string body =
        "set multiplot layout 2,1 title 'Device (" + ch + "_DEVICE_STATUS)'\nset xlabel 'time [s]'\n"
        "set ylabel 'tick lateness [us]'\nplot " + Csv("device_status.csv") +
        " skip 1 using 1:3 with lines title 'p50', '' skip 1 using 1:4 with lines title 'p99', "
        "'' skip 1 using 1:5 with lines title 'max'\n"
        "set ylabel 'model age [ms]'\nplot '' skip 1 using 1:6 with lines title 'model age'\n"
        "unset multiplot\n";
    RunGnuplot(dir, "device", body, out);
    // Histograms of the per-window statistics the device publishes (~2 Hz windows).
    const std::string hist =
        "set multiplot layout 1,2 title 'Latency histograms (" + ch + ")'\n"
        "stats " + Csv("device_status.csv") + " skip 1 using 5 nooutput\n"
        "w = STATS_max > 0 ? STATS_max / 40.0 : 1.0\nset boxwidth w\nset xrange [0:STATS_max + 2*w]\n"
        "set xlabel 'tick lateness per device window [us]'\nset ylabel 'windows'\n"
        "set style fill solid 0.5\n"
        "plot " + Csv("device_status.csv") + " skip 1 using (bin($3,w)):(1.0) smooth freq with boxes title 'p50', "
        "'' skip 1 using (bin($4,w)):(1.0) smooth freq with boxes title 'p99'\n" +
        (r.HasRoundTrip()
             ? "stats " + Csv("round_trip.csv") + " skip 1 using 2 nooutput\n"
               "w = STATS_max > 0 ? STATS_max / 40.0 : 1.0\nset boxwidth w\nset xrange [0:STATS_max + 2*w]\n"
               "set xlabel 'round trip, pose -> model as logged [us]'\nset ylabel 'models'\n"
               "plot " + Csv("round_trip.csv") + " skip 1 using (bin($2,w)):(1.0) smooth freq with boxes title 'round trip'\n"
             : "set xlabel 'round trip'\nunset key\nset label 1 'no pose/model pairs in the log' at graph 0.5, graph 0.5 center\n"
               "plot [0:1][0:1] NaN notitle\n") +
        "unset multiplot\n";
    RunGnuplot(dir, "latency_hist", hist, out);
  } else if (r.HasRoundTrip()) {
    const std::string hist =
        "stats " + Csv("round_trip.csv") + " skip 1 using 2 nooutput\n"
        "w = STATS_max > 0 ? STATS_max / 40.0 : 1.0\nset boxwidth w\nset xrange [0:STATS_max + 2*w]\nset style fill solid 0.5\n"
        "set title 'Round trip, pose -> model as logged (" + ch + ")'\n"
        "set xlabel 'round trip [us]'\nset ylabel 'models'\n"
        "plot " + Csv("round_trip.csv") + " skip 1 using (bin($2,w)):(1.0) smooth freq with boxes title 'round trip'\n";
    RunGnuplot(dir, "latency_hist", hist, out);
    AddNote(out, "device.png not drawn: no " + ch + "_DEVICE_STATUS messages");
  } else {
    AddNote(out, "device.png and latency_hist.png not drawn: no device status and no "
                 "pose/model pairs");
  }
}

}  // namespace

PlotOutcome MakePlots(const std::string& dir, const SessionReview& r) {
  PlotOutcome out;
  const std::string ch = SessionLabel(r.session());
  PlotForce(dir, r, ch, &out);
  if (r.HasForce()) PlotForceError(r, dir, ch, &out);
  PlotKnot(dir, r, ch, &out);
  PlotSolver(dir, r, ch, &out);
  PlotDevice(dir, r, ch, &out);
  return out;
}

}  // namespace snapthread::report
