‰SPS

