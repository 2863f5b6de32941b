#include "command.hpp"
#include "program.hpp"

#include <memory>
#include <stdexcept>
#include <system_error>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

namespace afmkit::cli {

CLI::App& add_command(CLI::App& parent, const std::string& name, const std::string& help, const Declare& declare,
                      Run run) {
  auto params = std::make_shared<io::ParamSet>();
  CLI::App* cmd = parent.add_subcommand(name, help);
  // The parameters and their options are built when the command's words begin to be parsed (CLI11's pre-parse
  // callback, before any of its options or --help): a run builds only the command that runs, not the whole tree
  // (start-up time, docs/development.md#start-up). Once: a second parse of the same app keeps them.
  cmd->preparse_callback([params, declare, cmd, declared = false](std::size_t) mutable {
    if (declared) return;
    declared = true;
    declare(*params);
    params->add_options(*cmd);
  });
  const CLI::App* root = cmd;
  std::string path = name;
  for (const CLI::App* up = cmd->get_parent(); up != nullptr; up = up->get_parent()) {
    root = up;
    if (up->get_parent() != nullptr) path = up->get_name() + " " + path;
  }
  if (auto* program = dynamic_cast<Program*>(const_cast<CLI::App*>(root)))
    program->commands.push_back({path, help, declare, run});
  cmd->callback([params, run = std::move(run)] {
    params->resolve();
    run(*params, nullptr);
  });
  return *cmd;
}

CLI::App& add_command_group(CLI::App& parent, const std::string& name, const std::string& help) {
  CLI::App* group = parent.add_subcommand(name, help);
  group->require_subcommand(1);
  return *group;
}

void add_json_flag(io::ParamSet& p, const std::string& help) { p.flag("json", false, help); }

void add_quiet_flag(io::ParamSet& p, const std::string& help) { p.flag("quiet", false, help); }

void add_output_params(io::ParamSet& p, const std::string& default_path, const std::string& what) {
  p.group("Output");
  add_json_flag(p);
  p.file("output", default_path, what + " CSV path (JSON sidecar describing every column next to it); empty: no file")
      .writes(io::table_and_sidecar);
}

CommandOutput::CommandOutput(const io::ParamSet& params, Captured* capture, std::string command,
                             const std::string& output_key)
    : params_(params), capture_(capture), command_(std::move(command)), path_(params.text(output_key)),
      json_(params.flag("json")) {
  keep_rows_ = capture_ != nullptr ? capture_->want_rows : json_ && path_.empty();
}

void CommandOutput::open(std::vector<io::Column> columns) { open_columns(io::ColumnList(std::move(columns))); }

void CommandOutput::open_columns(io::ColumnList columns) {
  columns_ = std::move(columns);
  if (!path_.empty()) file_.emplace(path_, columns_.vector());
}

void CommandOutput::finish(const nlohmann::json& results, const std::string& summary) {
  // a table declared as a grid: its dimensions and coordinates (checked against the rows written)
  const nlohmann::json grid = grid_.empty() ? nlohmann::json() : grid_.json();
  if (file_) {
    nlohmann::json sidecar = io::make_sidecar(command_, params_, results);
    if (!grid.is_null()) sidecar["grid"] = grid;
    file_->stage(sidecar, outputs_);
  }
  outputs_.commit();
  if (capture_ != nullptr) {
    if (capture_->take_results) capture_->take_results(results);
    else capture_->results = results;
    capture_->grid = grid;
    capture_->columns = std::move(columns_);
    capture_->rows = std::move(rows_);
    if (capture_->record_later != &params_) capture_->parameters = params_.to_json();
    return;
  }
  try {
    if (json_) {
      nlohmann::json document = results;
      if (keep_rows_) {
        document["table"] = {{"columns", io::columns_json(columns_.vector())}, {"rows", rows_}};
        if (!grid.is_null()) document["table"]["grid"] = grid;
      }
      else if (!path_.empty()) document["output"] = path_;
      fmt::print("{}\n", io::json_text(document));
    } else {
      if (!summary.empty()) fmt::print("{}\n", summary);
      if (!path_.empty())
        fmt::print("wrote {} rows to {} (columns, units and results in {}.json)\n", count_, path_, path_);
    }
  } catch (const std::system_error& e) {  // a full disk, a closed pipe (exit 1, as main's final check)
    throw std::runtime_error(fmt::format("cannot write the results to standard output: {}", e.code().message()));
  }
  require_answer(results);
}

void CommandOutput::finish(ResultsMaker make_results, const std::string& summary) {
  if (capture_ == nullptr || !capture_->take_results_maker || file_) {
    finish(make_results(), summary);
    return;
  }
  outputs_.commit();
  capture_->take_results_maker(std::move(make_results));
  capture_->grid = grid_.empty() ? nlohmann::json() : grid_.json();
  capture_->columns = std::move(columns_);
  capture_->rows = std::move(rows_);
  if (capture_->record_later != &params_) capture_->parameters = params_.to_json();
}

void require_answer(const nlohmann::json& results) {
  const auto status = results.find("status");
  if (status == results.end() || !status->is_string() || *status == "ok") return;
  const auto note = results.find("note");
  throw NoAnswer(fmt::format("status {}: {}", status->get<std::string>(),
                             note != results.end() && note->is_string() ? note->get<std::string>() : "no answer"));
}

}  // namespace afmkit::cli
