// The LinuxCNC target: a compiled program (the IR after the correction passes
// and their CompileState) lowered to RS274NGC for LinuxCNC's interpreter,
// and the output directory that holds it with the runtime subroutines
// (docs/linuxcnc.md has the lowering table, the directory and the checks).
//
// The main program calls the runtime (runtime/linuxcnc/*.ngc) for
// everything that happens on the controller: loading the cell's data, the
// marker scan and the correction of fixture and run-time targets. Static
// targets are the nominal coordinates the passes computed.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "backend/linuxcnc/embedded_files.h"
#include "backend/linuxcnc/linuxcnc_machine.h"
#include "base/diagnostics.h"
#include "base/result.h"
#include "base/source.h"
#include "base/text_output.h"
#include "ir/ir.h"
#include "passes/correction/compile_state.h"

namespace smtcal {

// What one compile writes besides the main program's text: its file name
// and the subroutine files.
struct LinuxCncOutput {
  std::string main_name;                  // "<program file stem>.ngc"
  std::vector<EmbeddedFile> subroutines;  // the runtime's files and smtcal_data.ngc, sorted by name
  std::vector<EmbeddedFile> dry_run;      // OUTDIR/dry-run/ (--dry-run-probe, linuxcnc_dry_run.h), or none
  std::vector<LinuxCncIoUse> io;          // the digital inputs and outputs the program and the cell use
  std::vector<EmbeddedFile> more_mains;   // further programs beside the main one (the measuring programs), or none
};

// Lowers the program, writing the main program's text to `main` as it is
// produced. What the target cannot express (a cell without a [linuxcnc]
// table, data the runtime cannot hold, an I/O bit LinuxCNC does not have, a
// pallet number known only at run time, a line too long for rs274) is
// reported to `diags`; nullopt, or errors in `diags`, leave `main`
// incomplete: never commit it then. `program_path` names the source in the
// output's comments (its file name only).
std::optional<LinuxCncOutput> EmitLinuxCnc(const ir::Program& program, const CompileState& state,
                                           const std::string& program_path, TextOutput& main, Diagnostics& diags);

// The o<pick_place> subroutine every main program with a Pick or Place holds
// (the cell's [linuxcnc] wiring, its final approach; `source_name` the
// program file named in its abort messages): written by the emitter, and
// compared by the reader of an output (linuxcnc_output.h).
std::string LinuxCncPickPlaceSubroutine(const cell::Cell& cell, std::string_view source_name);

// The name of the main program file for a source path: "layers.place" ->
// "layers.ngc" ("-" -> "program.ngc").
std::string LinuxCncMainName(const std::string& program_path);

// Every generated file for review on one stream: the main program, then
// smtcal_data.ngc, each after a "(smtcal file: PATH)" line. The runtime's
// own files are not repeated (they are runtime/linuxcnc/*.ngc verbatim).
std::string LinuxCncReviewText(const LinuxCncOutput& output, std::string_view main_text);

// The output directory OUTDIR: OUTDIR/<main_name>, the runtime in
// OUTDIR/subroutines/* and a machine for the cell (OUTDIR/<stem>.ini, .hal,
// .tbl, .var: EmitLinuxCncMachine) -- or, for a machine's INI given with
// --ini, the runtime in the folder its SUBROUTINE_PATH names, shared by every
// program compiled for that machine, and OUTDIR/<main_name> alone; with
// --dry-run-probe also OUTDIR/dry-run/. Each directory is written into a
// temporary sibling (DIR.tmp.PID) and swapped in by a rename at Commit(), the
// runtime first, so none is ever half-written; nothing is left behind when
// it is never committed. An existing directory is replaced only when it is
// an earlier smtcal output (its .ngc files open with smtcal's header line,
// subroutines/ and the runtime folder hold only smtcal_*.ngc, dry-run/ also
// rs274's files, the machine files are smtcal's or LinuxCNC's tool table
// and parameter file); anything else is refused by Open() with an Error
// naming what is in the way; the temporaries a killed smtcal left are
// removed the next time smtcal writes the same directory (as a file output's
// temporary is).
class LinuxCncDirectory {
 public:
  // `runtime`: the runtime's own folder (--ini), or empty: OUTDIR/subroutines.
  static Result<std::unique_ptr<LinuxCncDirectory>> Open(const std::filesystem::path& outdir,
                                                        const std::string& main_name,
                                                        const std::filesystem::path& runtime = {});
  ~LinuxCncDirectory();
  LinuxCncDirectory(const LinuxCncDirectory&) = delete;
  LinuxCncDirectory& operator=(const LinuxCncDirectory&) = delete;

  // The main program's file, written as EmitLinuxCnc produces it.
  TextOutput& main() { return *main_; }
  // Completes the main program, writes the runtime, the machine files and
  // the dry run, and swaps the directories in.
  Status Commit(const LinuxCncOutput& output, const std::vector<LinuxCncMachineFile>& machine = {});

 private:
  LinuxCncDirectory() = default;
  std::filesystem::path target_;
  std::filesystem::path temp_;
  bool replaces_ = false;  // OUTDIR exists (an earlier output)
  bool committed_ = false;
  std::filesystem::path runtime_;       // the runtime's own folder, or empty
  std::filesystem::path runtime_temp_;
  bool runtime_replaces_ = false;
  bool runtime_committed_ = false;
  std::unique_ptr<TextOutput> main_;
};

}  // namespace smtcal
