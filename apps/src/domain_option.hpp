// The `--domain D` option of the programs that run a simulator: the DDS domain
// it serves, claimed on this host for as long as the program runs
// (simsoccer/net/domain_claim.hpp), so that a second run cannot mix its
// robots' frames with this one's.
#pragma once

#include <cstdint>

#include "cli.hpp"
#include "simsoccer/net/domain_claim.hpp"

namespace simsoccer::apps {

// How a run without --domain finds its domain.
enum class DomainDefault {
  Fixed,      // `fallback` itself: agents started elsewhere are told to join it
  FirstFree,  // the first free one from `fallback` up: the run starts its own agents
};

// --domain D is claimed as given (refused, naming who holds it, when another
// run on this host does); without it, by `how`. `last` bounds the search
// (the credentials of --secure cover fewer domains than the RTPS range).
inline net::DomainClaim claimDomain(const Options& opt, uint32_t fallback, DomainDefault how,
                                    uint32_t last = 232) {
  if (opt.has("domain") || how == DomainDefault::Fixed)
    return net::DomainClaim::claim(opt.domain("domain", fallback));
  return net::DomainClaim::firstFree(fallback, last);
}

}  // namespace simsoccer::apps
