// parallax vocabulary train IMAGES... --out FILE [--branching K] [--depth L] [--iterations N]
//   [--seed S] [--features N]
// parallax vocabulary info FILE
// (docs/place_recognition.md, "Vocabulary").

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "backend/vocabulary.hpp"
#include "tools/commands/commands.hpp"
#include "tools/place/vocabulary_training_set.hpp"

namespace parallax::cli {
namespace {

struct TrainArgs {
  std::vector<std::string> images;
  std::string output;
  VocabularyTrainingOptions training;
  TrainingSetOptions set;
};

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

void PrintSummary(const std::string& name, const Vocabulary& v) {
  std::fputs(fmt::format("{}: k={} L={}, {} nodes, {} words, trained on {} images, {} bytes\n",
                         name, v.Branching(), v.Depth(), v.NumNodes(), v.NumWords(),
                         v.TrainingImages(), v.ToBytes().size())
                 .c_str(),
             stdout);
}

void RunTrain(TrainArgs args) {
  // The same file whatever order the shell listed the images in.
  std::sort(args.images.begin(), args.images.end());
  const auto start = std::chrono::steady_clock::now();
  const auto images = TrainingDescriptors(args.images, args.set);
  std::size_t descriptors = 0;
  for (const auto& image : images) descriptors += image.size();
  const double extract_ms = MillisecondsSince(start);
  const auto train_start = std::chrono::steady_clock::now();
  const Vocabulary vocabulary = Vocabulary::Train(images, args.training);
  const double train_ms = MillisecondsSince(train_start);
  vocabulary.Save(args.output);
  std::fputs(
      fmt::format("{} photographs, {} views, {} descriptors (ORB {:.1f} s), trained in "
                  "{:.1f} s\n",
                  args.images.size(), images.size(), descriptors, extract_ms / 1e3, train_ms / 1e3)
          .c_str(),
      stdout);
  PrintSummary(args.output, vocabulary);
}

void RunInfo(const std::string& path) {
  const auto start = std::chrono::steady_clock::now();
  const Vocabulary vocabulary = path == "default" ? Vocabulary::Default() : Vocabulary::Load(path);
  const double load_ms = MillisecondsSince(start);
  PrintSummary(path, vocabulary);
  std::fputs(fmt::format("loaded in {:.1f} ms\n", load_ms).c_str(), stdout);
}

}  // namespace

void AddVocabularyCommand(CLI::App& app, int* exit_code) {
  CLI::App* cmd = app.add_subcommand("vocabulary", "Place-recognition vocabulary (ORB words)");
  cmd->require_subcommand(1);
  auto train = std::make_shared<TrainArgs>();
  CLI::App* t = cmd->add_subcommand("train", "Train a vocabulary on photographs");
  t->add_option("images", train->images, "image files (generic photographs)")->required();
  t->add_option("--out", train->output, "vocabulary file to write")->required();
  t->add_option("--branching", train->training.branching, "k: children per node")
      ->check(CLI::Range(2, 255));
  t->add_option("--depth", train->training.depth, "L: levels below the root")
      ->check(CLI::Range(1, 16));
  t->add_option("--iterations", train->training.max_iterations, "k-majority iterations per node")
      ->check(CLI::PositiveNumber);
  t->add_option("--seed", train->training.seed, "random seed");
  t->add_option("--features", train->set.orb.max_features, "ORB features per view")
      ->check(CLI::PositiveNumber);
  t->callback([train, exit_code] {
    RunTrain(*train);
    *exit_code = 0;
  });
  auto info_path = std::make_shared<std::string>();
  CLI::App* i = cmd->add_subcommand("info", "Describe a vocabulary file ('default': built in)");
  i->add_option("file", *info_path, "vocabulary file or 'default'")->required();
  i->callback([info_path, exit_code] {
    RunInfo(*info_path);
    *exit_code = 0;
  });
}

}  // namespace parallax::cli
