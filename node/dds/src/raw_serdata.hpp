// A minimal Cyclone DDS serdata that carries already-serialised CDR bytes, and the sertype rbsim's
// writers are created with, so rbsim publishes exactly the bytes rbsim_msgs encoded without going
// through C structs. A writer of the idlc-generated type would take such a serdata too, but
// converts it to its own type first (dds_writecdr: a copy and a walk over every element to
// validate it); a writer of the raw type sends it as it is. The raw type carries no XTypes type
// information, so readers match it by type name, as they match rmw_cyclonedds_cpp's writers.
#pragma once

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>

#include <cstddef>
#include <span>
#include <string>

#include "rbsim/status.hpp"

namespace rbsim::node {
// A new sertype named `type_name` (the ROS 2 DDS type name) whose serdata are raw CDR, for
// dds_create_topic_sertype, which takes it over (it is freed with the last topic using it).
ddsi_sertype* make_raw_sertype(const char* type_name);
// A new serdata of `type` (a raw sertype) holding a copy of `cdr` (the 4-byte encapsulation header
// included); the caller owns one reference (dds_writecdr takes it over).
ddsi_serdata* make_raw_serdata(const ddsi_sertype* type, std::span<const std::byte> cdr);
// The topic `name` with a new raw sertype named `type_name`: rbsim's writers send the bytes
// rbsim_msgs encoded as they are, its readers take them as they came. `sertype` (optional)
// receives the sertype the topic uses (Cyclone may swap in an equal one it already has). The one
// maker of rbsim's DDS topics: the DDS wrappers (dds.cpp) and the services (service.cpp).
Result<dds_entity_t> make_raw_topic(dds_entity_t participant, const std::string& name,
                                    const std::string& type_name, const ddsi_sertype** sertype = nullptr);
// "<what>: <Cyclone's text for rc>".
Error dds_error(const std::string& what, dds_return_t rc);
}  // namespace rbsim::node
