#pragma once
// Small statistics for the rankings of conditions against a seeded truth (docs/pathtraced.md, "Reading the
// agreement"): Student's t quantiles for a jackknife over few seeds, sample quantiles, percentile intervals of a
// bootstrap, and Tukey's upper fence, which defines the "clearly worse" conditions.
#include <array>
#include <cstddef>
#include <vector>

namespace skinlab::metrics {

// Student's t distribution with `degreesOfFreedom` > 0: its CDF and its quantile (inverse CDF) for 0 < p < 1.
// NaN for arguments outside those ranges. t_{0.975}(3) = 3.182446…, t_{0.975}(1) = 12.7062…
double studentTCdf(double t, double degreesOfFreedom);
double studentTQuantile(double probability, double degreesOfFreedom);

// The sample quantile with linear interpolation between order statistics (Hyndman & Fan type 7, R's default and
// numpy's "linear"): h = (n − 1)·p, x_(⌊h⌋) + (h − ⌊h⌋)(x_(⌊h⌋+1) − x_(⌊h⌋)). Non-finite values are dropped; NaN
// if none remain.
double sampleQuantile(std::vector<double> values, double probability);

// The central percentile interval [q_{(1−level)/2}, q_{(1+level)/2}] of bootstrap replicates (type 7 quantiles,
// non-finite replicates dropped); NaN bounds if fewer than two finite replicates.
std::array<double, 2> percentileInterval(std::vector<double> replicates, double level);

// Tukey's upper fence Q3 + 1.5·(Q3 − Q1) (type 7 quartiles): a condition whose error lies above it is "clearly
// worse" than the others (Tukey 1977, Exploratory Data Analysis). NaN for fewer than four finite values.
double upperTukeyFence(const std::vector<double>& values);

// The indices of the `count` smallest finite values, ascending by value (ties by index); all finite indices when
// there are fewer.
std::vector<std::size_t> smallestIndices(const std::vector<double>& values, std::size_t count);

} // namespace skinlab::metrics
