// check-header: the lines every program starts with.
//
// Assumes: an IR that passes the verifier; nothing about order.
// Guarantees when it reports no error: exactly one `Program NAME`, and it is
// the first statement (comments may precede it); exactly one `Units`, and it
// is mm (case-insensitive); at most one top-level `Vacuum n`; a function
// named Main exists (the entry point). Reads the IR, never changes it.
#include "ir/symbols.h"
#include "passes/checks/checks.h"

namespace smtcal {
namespace {

class CheckHeader final : public Pass {
 public:
  std::string_view Name() const override { return "check-header"; }

  void Run(ir::Program& program, Diagnostics& diags) override {
    const ir::Stmt* first = nullptr;
    const ir::Stmt* program_decl = nullptr;
    const ir::Stmt* units_decl = nullptr;
    const ir::Stmt* vacuum_decl = nullptr;
    bool has_main = false;

    // The first of each header line is kept; later ones are reported.
    auto once = [&](const ir::Stmt& stmt, const ir::Stmt*& seen, const char* keyword) {
      if (seen == nullptr) {
        seen = &stmt;
        return true;
      }
      Diagnostic* diag = diags.Report(DiagKind::RepeatedDeclaration, sema::StmtRange(stmt), keyword);
      Diagnostics::AddNote(diag, sema::StmtRange(*seen), fmt::format("the first '{}' line is here", keyword));
      return false;
    };

    for (const ir::StmtPtr& item : program.items) {
      const ir::Stmt& stmt = *item;
      if (std::holds_alternative<ir::Comment>(stmt.node)) continue;
      if (first == nullptr) first = &stmt;
      if (const auto* decl = std::get_if<ir::ProgramDecl>(&stmt.node)) {
        if (once(stmt, program_decl, "Program") && &stmt != first) {
          Diagnostic* diag = diags.Report(DiagKind::ProgramNotFirst, sema::StmtRange(stmt), decl->name);
          Diagnostics::AddNote(diag, sema::StmtRange(*first), "the file starts with this statement instead");
        }
      } else if (const auto* units = std::get_if<ir::UnitsDecl>(&stmt.node)) {
        if (once(stmt, units_decl, "Units") && !sema::SameName(units->unit, "mm")) {
          diags.Report(DiagKind::UnsupportedUnit, sema::NameAt(units->unit_loc, units->unit), units->unit);
        }
      } else if (std::holds_alternative<ir::VacuumDecl>(stmt.node)) {
        once(stmt, vacuum_decl, "Vacuum");
      } else if (const auto* function = std::get_if<ir::Function>(&stmt.node)) {
        if (sema::SameName(function->name, "Main")) has_main = true;
      }
    }

    // Whole-program omissions point at the Program line, or at the top.
    SourceRange top = program_decl != nullptr ? sema::StmtRange(*program_decl)
                                              : SourceRange(SourceLoc{program.file, 1, 1});
    if (program_decl == nullptr) diags.Report(DiagKind::MissingProgram, top);
    if (units_decl == nullptr) diags.Report(DiagKind::MissingUnits, top);
    if (!has_main) diags.Report(DiagKind::MissingMain, top);
  }
};

}  // namespace

std::unique_ptr<Pass> CreateCheckHeaderPass() { return std::make_unique<CheckHeader>(); }

}  // namespace smtcal
