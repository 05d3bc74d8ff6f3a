// The precompiled headers' own translation unit (cmake/SlamdunkPrecompiledHeaders.cmake).
