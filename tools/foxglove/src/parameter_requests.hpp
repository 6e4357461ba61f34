// What the server does to a setParameters request before the steering sees it, apart from its
// own state (src/parameters.cpp): the names checked against the node's, untyped integers typed.
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

#include "rbsim/foxglove.hpp"

namespace rbsim::foxglove::detail {

// Keeps the values on parameters the node has (`index`: its names), in order, and names them in
// `r.names`; each other one is a problem.
void keep_known_names(ParameterRequest& r, const std::unordered_map<std::string, std::size_t>& index,
                      std::vector<std::string>& problems);

// A JSON integer for a double parameter is that double (JSON cannot tell 2 from 2.0), if exact;
// `types` are the declared types of `r.values`.
void type_untyped_integers(ParameterRequest& r, const std::vector<msgs::ParameterType>& types);

}  // namespace rbsim::foxglove::detail
