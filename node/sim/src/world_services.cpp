// simulation_interfaces' world services on the node (simulation_services.hpp): LoadWorld,
// UnloadWorld, GetCurrentWorld and GetAvailableWorlds. A world is a FOSSSim scene, given as its text
// (resource_string) or as a uri naming a file of the worlds folders (rbsim node --worlds, the
// bundled scenes by default; resource_folder.hpp's one policy). It is read and parsed here, off the
// loop's thread, then loaded at the next step boundary as a load_world command carrying the
// scene's text, so a recording re-simulates it without the file. While that goes on the state is
// STATE_LOADING_WORLD; a world that does not load leaves the running one untouched.
#include <filesystem>
#include <memory>
#include <string>

#include "rbsim/counts.hpp"
#include "rbsim/scene.hpp"
#include "simulation_services.hpp"

namespace rbsim::node {

namespace {

namespace sim = msgs::simulation;
using control::Command;
using control::CommandKind;
using control::CommandResult;
using sim::Result;
using simulation_detail::failure;
using simulation_detail::ok;
using simulation_detail::refuse_malformed;
using Load = sim::LoadWorldResponse;

using simulation_detail::kMaxFolderEntries;
using simulation_detail::kMaxListingBytes;
using simulation_detail::kMaxWorldBytes;
// GetAvailableWorlds: at most this many scenes listed.
constexpr std::size_t kMaxWorlds = 10000;
constexpr std::string_view kSceneSuffix = ".xml";

// Clears the flag when the load is over, however it ends.
struct Loading {
  std::atomic<bool>& flag;
  explicit Loading(std::atomic<bool>& f) : flag(f) { flag.store(true); }
  ~Loading() { flag.store(false); }
  Loading(const Loading&) = delete;
  Loading& operator=(const Loading&) = delete;
};

sim::WorldResource world_resource(const control::WorldInfo& info) {
  sim::WorldResource w;
  w.name = info.name;
  w.world_resource.uri = info.path;
  w.description = info.description;
  return w;
}

// The scene text a request names (its uri's file, else its resource_string, as Resource.msg says),
// or the refusal: a uri outside the worlds folders, or no such
// file, is NO_RESOURCE; one too large RESOURCE_PARSE_ERROR (as a resource_string over the limit).
struct WorldText {
  std::string text, source;
  std::optional<Result> refused;
};
WorldText world_text(const sim::Resource& res, const ResourceFolders& folders) {
  WorldText w;
  if (res.uri.empty() && res.resource_string.empty()) {
    w.refused = failure(Load::kNoResource, "world_resource: both uri and resource_string are empty");
    return w;
  }
  if (res.uri.empty()) {  // Resource.msg: the text is used only without a uri
    if (res.resource_string.size() > kMaxWorldBytes) {
      w.refused = failure(Load::kResourceParseError,
                          "world_resource.resource_string: " + group_digits(res.resource_string.size()) +
                              " bytes, more than the " + group_digits(kMaxWorldBytes) + " a world may have");
      return w;
    }
    w.text = res.resource_string;
    w.source = "resource_string";
    return w;
  }
  if (folders.empty()) {
    w.refused = failure(Load::kNoResource, "world_resource.uri '" + res.uri +
                                               "': this node reads no world files (rbsim node --worlds DIR)");
    return w;
  }
  if (!res.uri.ends_with(kSceneSuffix)) {
    w.refused = failure(Load::kUnsupportedFormat,
                        "world_resource.uri '" + res.uri + "': a world is a FOSSSim scene, a .xml file");
    return w;
  }
  ResourceFolders::Text t = folders.read(res.uri, kMaxWorldBytes);
  switch (t.refusal) {
    case ResourceFolders::Refusal::None:
      w.text = std::move(t.text);
      w.source = res.uri;
      return w;
    case ResourceFolders::Refusal::TooLarge:
      w.refused = failure(Load::kResourceParseError, "world_resource." + t.message);
      return w;
    default:
      w.refused = failure(Load::kNoResource, "world_resource." + t.message);
      return w;
  }
}

}  // namespace

// LoadWorld: the scene read and parsed here (its errors name the source, the line and the rule),
// then loaded at the next boundary. fail_on_unsupported_element refuses a scene with unknown
// elements or attributes (UNSUPPORTED_ELEMENTS, the loader's warnings); without it they are
// ignored, as the scene loader does. ignore_missing_or_unsupported_assets changes nothing: a
// FOSSSim scene has no assets.
Load SimulationServices::load_world(const sim::LoadWorldRequest& req) {
  const Loading loading(loading_);
  WorldText w = world_text(req.world_resource, worlds_);
  if (w.refused) return Load{*w.refused, {}};
  rbsim::Result<Scene> parsed = parse_scene(w.text, w.source);
  if (!parsed) return Load{failure(Load::kResourceParseError, parsed.error().message), {}};
  if (req.fail_on_unsupported_element && !parsed.value().warnings.empty()) {
    std::string all;
    for (const std::string& warning : parsed.value().warnings) all += (all.empty() ? "" : "; ") + warning;
    return Load{failure(Load::kUnsupportedElements, all), {}};
  }
  Command c;
  c.kind = CommandKind::LoadWorld;
  c.world.resource = std::move(w.text);
  c.world.uri = req.world_resource.uri;
  c.world.scene = std::make_shared<const Scene>(std::move(parsed.value()));
  const CommandResult r = apply_(std::move(c));
  if (!r.successful) {
    const std::uint8_t code =
        r.refusal == control::Refusal::BadResource ? Load::kResourceParseError : Result::kOperationFailed;
    return Load{failure(code, r.message), {}};
  }
  stopped_.store(true);  // a loaded world starts stopped
  return Load{ok(), world_resource(controller_.world_info())};
}

sim::UnloadWorldResponse SimulationServices::unload_world() {
  Command c;
  c.kind = CommandKind::UnloadWorld;
  const CommandResult r = apply_(std::move(c));
  if (r.successful) return sim::UnloadWorldResponse{ok()};
  return sim::UnloadWorldResponse{failure(r.refusal == control::Refusal::NoWorld
                                              ? sim::UnloadWorldResponse::kNoWorldLoaded
                                              : Result::kOperationFailed,
                                          r.message)};
}

sim::GetCurrentWorldResponse SimulationServices::current_world() const {
  const control::WorldInfo info = controller_.world_info();
  if (!info.loaded) {
    return sim::GetCurrentWorldResponse{
        failure(sim::GetCurrentWorldResponse::kNoWorldLoaded, "no world is loaded (load_world loads one)"),
        {}};
  }
  return sim::GetCurrentWorldResponse{ok(), world_resource(info)};
}

// GetAvailableWorlds: the scenes (*.xml) of the worlds folders, each named by its file's stem, with
// its description; one that does not parse is left out, and the result's message says so. Tags:
// rbsim's worlds have none (a tag filter is FEATURE_UNSUPPORTED); other sources are not searched.
sim::GetAvailableWorldsResponse SimulationServices::available_worlds(
    const sim::GetAvailableWorldsRequest& req) const {
  using Res = sim::GetAvailableWorldsResponse;
  if (worlds_.empty())
    return Res{failure(Result::kFeatureUnsupported, "no worlds folder (rbsim node --worlds DIR)"), {}};
  if (!req.filter.tags.empty())
    return Res{failure(Result::kFeatureUnsupported, "rbsim's worlds have no tags (WORLD_TAGS is not listed)"),
               {}};
  const ResourceFolders::Listing listing = worlds_.list(kSceneSuffix, kMaxWorlds, kMaxFolderEntries);
  if (!listing.refused.empty()) return Res{failure(Result::kOperationFailed, listing.refused), {}};
  Res res{ok(), {}};
  std::vector<std::string> notes;
  std::size_t read = 0, unread = 0;
  for (const ResourceFolders::Entry& e : listing.files) {
    sim::WorldResource w;
    w.name = std::filesystem::path(e.uri).stem().string();
    w.world_resource.uri = e.uri;
    if (read >= kMaxListingBytes) {
      ++unread;
      res.worlds.push_back(std::move(w));
      continue;
    }
    const ResourceFolders::Text t = worlds_.read(e.uri, kMaxWorldBytes);
    read += t.text.size();
    rbsim::Result<Scene> scene = t.refusal == ResourceFolders::Refusal::None
                                     ? parse_scene(t.text, e.uri)
                                     : rbsim::Result<Scene>(Error{t.message});
    if (!scene) {
      notes.push_back("left out " + scene.error().message);
      continue;
    }
    w.description = scene.value().description;
    res.worlds.push_back(std::move(w));
  }
  if (unread > 0)
    notes.push_back(group_digits(unread) + " " + plural(unread, "world", "worlds") +
                    " listed without description (a call reads at most " + group_digits(kMaxListingBytes) +
                    " bytes of scenes)");
  if (!req.additional_sources.empty())
    notes.push_back("additional sources not searched: only the worlds folder is");
  for (const std::string& note : notes)
    res.result.error_message += (res.result.error_message.empty() ? "" : "; ") + note;
  return res;
}

void SimulationServices::add_worlds(std::vector<Entry>& out) {
  out.emplace_back(
      "load_world", std::string(sim::LoadWorldRequest::kService),
      typed_handler<sim::LoadWorldRequest, Load>(
          [this](const RequestHeader&, const sim::LoadWorldRequest& req) { return load_world(req); },
          refuse_malformed<Load>()));
  out.emplace_back(
      "unload_world", std::string(sim::UnloadWorldRequest::kService),
      typed_handler<sim::UnloadWorldRequest, sim::UnloadWorldResponse>(
          [this](const RequestHeader&, const sim::UnloadWorldRequest&) { return unload_world(); },
          refuse_malformed<sim::UnloadWorldResponse>()));
  out.emplace_back(
      "get_current_world", std::string(sim::GetCurrentWorldRequest::kService),
      typed_handler<sim::GetCurrentWorldRequest, sim::GetCurrentWorldResponse>(
          [this](const RequestHeader&, const sim::GetCurrentWorldRequest&) { return current_world(); },
          refuse_malformed<sim::GetCurrentWorldResponse>()));
  out.emplace_back("get_available_worlds", std::string(sim::GetAvailableWorldsRequest::kService),
                   typed_handler<sim::GetAvailableWorldsRequest, sim::GetAvailableWorldsResponse>(
                       [this](const RequestHeader&, const sim::GetAvailableWorldsRequest& req) {
                         return available_worlds(req);
                       },
                       refuse_malformed<sim::GetAvailableWorldsResponse>()));
}

}  // namespace rbsim::node
