// A minimal Cyclone DDS serdata that carries already-serialised CDR bytes. dds_writecdr converts
// it to the writer's own type (one copy, validated by Cyclone), so rbsim publishes exactly the
// bytes rbsim_msgs encoded without going through C structs. (Cyclone 0.10 has no public way to
// obtain a topic's own sertype; 0.11's dds_get_entity_sertype would make this unnecessary.)
#pragma once

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>

#include <cstddef>
#include <span>

namespace rbsim::node {
// A new serdata holding a copy of `cdr` (the 4-byte encapsulation header included); the caller
// owns one reference (dds_writecdr takes it over).
ddsi_serdata* make_raw_serdata(std::span<const std::byte> cdr);
}  // namespace rbsim::node
