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

namespace rbsim::node {
// A new sertype named `type_name` (the ROS 2 DDS type name) whose serdata are raw CDR, for
// dds_create_topic_sertype, which takes it over (it is freed with the last topic using it).
ddsi_sertype* make_raw_sertype(const char* type_name);
// A new serdata of `type` (a raw sertype) holding a copy of `cdr` (the 4-byte encapsulation header
// included); the caller owns one reference (dds_writecdr takes it over).
ddsi_serdata* make_raw_serdata(const ddsi_sertype* type, std::span<const std::byte> cdr);
}  // namespace rbsim::node
