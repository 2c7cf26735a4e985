// report.json of a lace job: the chart's constraint check and fitness terms, the evolution
// (generations, best score per generation, feasible count), what the lace carriage of a
// Brother machine can and cannot do with the swatch (plans it for a KH-930: the device plans
// again with its own machine), what the preview shows, the parameters and timings.
// Pure; thread-safe.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "algorithms/lace/evolve.h"
#include "algorithms/lace/preview.h"
#include "convert/convert.h"
#include "convert/lace/lace_chart_json.h"
#include "convert/lace/lace_params.h"

namespace atelier {

nlohmann::json lace_report_json(const ConvertRequest& req, const std::string& title, const LaceParams& params,
                                const std::optional<LaceChartFile>& start, const lace::EvolveResult& result,
                                const lace::PreviewOptions& preview, double evolve_s, double outputs_s);

}  // namespace atelier
